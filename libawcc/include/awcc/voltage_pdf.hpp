#pragma once
// The voltage PDF of a tip (METHOD.md 8): the fraction of samples in each
// voltage bin, from the histogram binarisation gathered.
//
// Default: bins [k w, (k + 1) w) over the observed range, fraction = count / N.
// Felder's program (felder-program.md 1): 60 bins with float32 upper edges
// e_k = fl32(-1 + fl32(0.1 k)), k = 1..60, a sample in the first bin with
// V < e_k (the first also takes everything below -0.9 V, none above 5 V),
// each labelled by its upper edge, fraction fl32(count / N).

#include <cstdint>
#include <vector>

#include "awcc/binarisation.hpp"

namespace awcc {

struct VoltagePdf {
  std::vector<double> lower, upper;   ///< V: bin edges (Felder: lower of the first bin is -inf)
  std::vector<double> fraction;       ///< -
  std::int64_t samples = 0;
};

/// Bins of width w (V) covering the histogram's range.
VoltagePdf voltage_pdf(const VoltageHistogram& histogram, double width);
/// Felder's 60 bins from -1 V to 5 V.
VoltagePdf felder_voltage_pdf(const VoltageHistogram& histogram);

}  // namespace awcc
