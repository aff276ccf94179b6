#pragma once
// Bias correction with uncertainty, METHOD.md 7: two quantile regression
// forests (awcc/quantile_forest.hpp) map what AWCC measured to the
// distribution of the truth.
//
// Features (in this order): measured mean velocity u (m/s), measured
// turbulence intensity Tu, measured void fraction c, measured Sauter diameter
// d32 = 1.5 u c / F (m), tip separations dx and dy (m), particles per window
// Np. Targets: the true mean velocity and the true Tu, each learnt in the form
// the model names (TargetForm) and mapped back:
//   value       t = y_true                  y_q = t_q
//   ratio       t = y_true / y_measured     y_q = y_measured t_q   (y_measured > 0)
//   difference  t = y_true - y_measured     y_q = y_measured + t_q
// Each map is increasing in t, so quantiles of t give quantiles of y_true.
// Turbulence intensities are not negative: their quantiles are clipped at 0,
// which is the quantile of the clipped distribution.
//
// A row is corrected only inside the training data: every feature within its
// training [min, max] widened by `range_margin` of the span on each side
// (the trees split between training values, so beyond the data they repeat
// the edge leaf: that is extrapolation), and at least `min_windows` accepted
// windows (runs with fewer were left out of training). Otherwise the row is
// flagged with the reason and left uncorrected.
//
// Model file (".qrf"), all numbers little-endian whatever the machine:
//   "pdp-qrf\n" (8 bytes), u32 format version, u64 payload bytes, payload,
//   u32 CRC-32 (IEEE 802.3) of everything before it.
// Payload: provenance text; features (name, min, max); range margin; minimum
// windows; per forest its name, target form, feature count, training targets
// (f64), tree count, the width of a held row (u8: 2 or 4 bytes; 2 when there
// are at most 65,536 targets) and the trees: node count, nodes (a split: u8
// feature, f64 threshold, u32 left child, the right child being left + 1; a
// leaf: u8 0xff, u32 first held row, u32 count), held-row count (u64), held
// rows.
// A file that is not a model, of a newer version, truncated or damaged is
// refused with a message naming the file and the fix.

#include <array>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "awcc/process.hpp"
#include "awcc/quantile_forest.hpp"

namespace awcc {

/// The quantile levels every correction reports.
inline constexpr std::array<double, 7> correction_levels{0.025, 0.1, 0.25, 0.5, 0.75, 0.9, 0.975};
/// Their JSON keys and CSV suffixes.
inline constexpr std::array<const char*, 7> correction_level_names{"0.025", "0.1", "0.25", "0.5", "0.75", "0.9", "0.975"};

enum class TargetForm : std::uint8_t { value = 0, ratio = 1, difference = 2 };
std::string_view to_string(TargetForm f);

/// What the forests see, in feature order.
struct CorrectionFeatures {
  static constexpr int count = 7;
  static constexpr std::array<const char*, 7> names{"velocity", "turbulence_intensity", "void_fraction", "d32", "dx", "dy", "np"};
  double velocity = 0.0, turbulence_intensity = 0.0, void_fraction = 0.0, d32 = 0.0, dx = 0.0, dy = 0.0, np = 0.0;
  std::int64_t windows_accepted = 0;  ///< not a feature: rows below the model's minimum are not corrected
  [[nodiscard]] std::array<double, 7> vector() const {
    return {velocity, turbulence_intensity, void_fraction, d32, dx, dy, np};
  }
};

struct FeatureRange {
  std::string name;
  double min = 0.0, max = 0.0;
};

struct CorrectedQuantity {
  double measured = 0.0;
  std::array<double, 7> quantiles{};  ///< at correction_levels
  [[nodiscard]] double median() const { return quantiles[3]; }
};

struct Correction {
  bool in_range = false;
  std::string reason;                 ///< why not, when out of range
  std::optional<CorrectedQuantity> velocity, turbulence_intensity;
};

struct CorrectionModel {
  static constexpr std::uint32_t format_version = 1;

  std::string provenance;             ///< how the model was made (sweep, rows, options, held-out scores)
  std::vector<FeatureRange> ranges;   ///< training data [min, max] per feature, feature order
  double range_margin = 0.01;         ///< fraction of each span added on both sides
  std::int64_t min_windows = 100;     ///< least accepted windows of a corrected row
  TargetForm velocity_form = TargetForm::ratio;
  TargetForm turbulence_form = TargetForm::difference;
  QuantileForest velocity, turbulence_intensity;

  /// Empty when the features are inside the training data, else why not.
  [[nodiscard]] std::string out_of_range(const CorrectionFeatures& f) const;
  [[nodiscard]] Correction correct(const CorrectionFeatures& f) const;

  [[nodiscard]] std::vector<std::uint8_t> serialise() const;
  /// `name` is used in messages only.
  static CorrectionModel parse(const std::vector<std::uint8_t>& bytes, const std::string& name);
  /// Written to a temporary name and renamed when complete.
  void save(const std::filesystem::path& path) const;
  static CorrectionModel load(const std::filesystem::path& path);
};

/// The forest target of a truth given the measurement, and back.
double to_target(TargetForm form, double truth, double measured);
double from_target(TargetForm form, double target, double measured);

/// Features of a processed recording; empty (with the reason) when AWCC did
/// not run or gave no value, or the count rate is zero.
std::optional<CorrectionFeatures> correction_features(const ProcessResult& r, std::string* why = nullptr);

/// A row that is not corrected, with the reason.
Correction not_corrected(std::string reason);

/// Profile CSV columns of a correction (no leading comma): correction_in_range,
/// correction_reason, corrected_velocity (median), corrected_velocity_q0.025 ..
/// _q0.975, and the same for turbulence_intensity.
std::string correction_csv_header();
std::string correction_csv_cells(const Correction& c);

/// {"in_range", "reason", "velocity": {"measured", "median", "quantiles": {"0.025": ...}}, "turbulence_intensity": ...}
nlohmann::json to_json(const Correction& c);

/// CRC-32 (IEEE 802.3, reflected, as zlib's crc32).
std::uint32_t crc32(const std::uint8_t* data, std::size_t size);

}  // namespace awcc
