#include "awcc/voltage_pdf.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace awcc {

VoltagePdf voltage_pdf(const VoltageHistogram& histogram, double width) {
  if (!(width > 0.0)) throw std::invalid_argument("voltage PDF: the bin width must be > 0");
  VoltagePdf p;
  p.samples = histogram.total();
  const auto bins = histogram.regroup(width);
  if (bins.empty()) return p;
  const std::int64_t first = bins.front().first, last = bins.back().first;
  const auto size = static_cast<std::size_t>(last - first + 1);
  std::vector<std::int64_t> counts(size, 0);
  for (const auto& [bin, count] : bins) counts[static_cast<std::size_t>(bin - first)] += count;
  for (std::size_t i = 0; i < size; ++i) {
    const auto k = static_cast<double>(first + static_cast<std::int64_t>(i));
    p.lower.push_back(k * width);
    p.upper.push_back((k + 1.0) * width);
    p.fraction.push_back(static_cast<double>(counts[i]) / static_cast<double>(p.samples));
  }
  return p;
}

VoltagePdf felder_voltage_pdf(const VoltageHistogram& histogram) {
  constexpr int bins = 60;
  VoltagePdf p;
  p.samples = histogram.total();
  std::vector<float> edges(bins);
  for (int k = 1; k <= bins; ++k) edges[static_cast<std::size_t>(k - 1)] = -1.0f + static_cast<float>(k) * 0.1f;
  std::vector<std::int64_t> counts(bins, 0);
  for (const auto& [value, count] : histogram.values()) {
    const auto v = static_cast<float>(value);
    for (int k = 0; k < bins; ++k) {
      if (v < edges[static_cast<std::size_t>(k)]) {
        counts[static_cast<std::size_t>(k)] += count;
        break;
      }
    }
  }
  const auto n = static_cast<float>(p.samples);
  for (int k = 0; k < bins; ++k) {
    p.lower.push_back(k == 0 ? -std::numeric_limits<double>::infinity() : edges[static_cast<std::size_t>(k - 1)]);
    p.upper.push_back(edges[static_cast<std::size_t>(k)]);
    p.fraction.push_back(static_cast<float>(static_cast<float>(counts[static_cast<std::size_t>(k)]) / n));
  }
  return p;
}

}  // namespace awcc
