// The correction of one row: its features against the training ranges,
// the forests' distributions, the calibration and the trust rules.

#include "correction/model.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <deque>
#include <fstream>
#include <iterator>

#include <cerrno>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <stdexcept>
#include <zlib.h>

#include "awcc/atomic_output.hpp"
#include "awcc/awcc.hpp"
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/read_back.hpp"
#include "correction/modality.hpp"

namespace correction {

std::string_view to_string(TargetForm f) {
  switch (f) {
    case TargetForm::value: return "value";
    case TargetForm::ratio: return "ratio";
    case TargetForm::difference: return "difference";
  }
  return "unknown";
}

double to_target(TargetForm form, double truth, double measured) {
  switch (form) {
    case TargetForm::value: return truth;
    case TargetForm::ratio: return truth / measured;
    case TargetForm::difference: return truth - measured;
  }
  return truth;
}

double from_target(TargetForm form, double target, double measured) {
  switch (form) {
    case TargetForm::value: return target;
    case TargetForm::ratio: return target * measured;
    case TargetForm::difference: return target + measured;
  }
  return target;
}

Correction not_corrected(CorrectionStatus status, std::string message) {
  Correction c;
  c.status = status;
  c.message = std::move(message);
  return c;
}


namespace {

// Where a row's missing record feature comes from: the columns pdp process
// writes (read from any CSV), or the setting stated for a whole file (pdp correct --fs, --duration).
std::string how_to_give(const std::string& feature) {
  if (feature == "fs" || feature == "duration") {
    return fmt::format("a column '{}', or the {} stated for the whole file", feature, feature);
  }
  namespace column = awcc::profile_column;
  if (feature == "windows_accepted") {
    return fmt::format("a column '{}': AWCC's accepted windows of the row", column::awcc_windows_accepted);
  }
  if (feature == "data_yield") {
    return fmt::format("columns '{}' and '{}': AWCC's accepted and formed windows of the row",
                       column::awcc_windows_accepted, column::awcc_windows_total);
  }
  return fmt::format("a column '{}'", feature);
}

// What a value outside its training range means, in the field's words
// where the flow itself is outside what the simulator models.
std::string out_of_range_meaning(const FeatureRange& r, double v) {
  if (r.name == "void_fraction" && v > 0.5) {
    return ": above c = 0.5 the flow is droplets in air, which this model was not trained on (its campaigns stop at c = 0.6; the synthetic probe models the spray region since issue 31)";
  }
  if (r.name == "duration" && v < r.min) return ": a shorter record holds less than any the model learnt from";
  return {};
}

std::string out_of_range_reason(const FeatureRange& r, double v) {
  return fmt::format("{} is outside the training range {}{}", feature_value_text(r.name, v),
                     feature_range_text(r.name, r.min, r.max), out_of_range_meaning(r, v));
}

// A forest's features of a row: x, or why the row cannot be corrected (a
// feature not known, or outside the training range). A record longer than
// the longest training record is held at that length, with a note (the
// model's header says why duration alone is held).
struct FeatureVector {
  std::vector<double> x;
  CorrectionStatus status = CorrectionStatus::corrected;
  std::string message;
  std::vector<std::string> notes;
  const FeatureRange* refused = nullptr;  ///< the feature outside its range
  [[nodiscard]] bool ok() const { return status == CorrectionStatus::corrected; }
};

}  // namespace

FeatureRange accepted_range(const FeatureRange& training, double margin) {
  FeatureRange r = training;
  const double pad = margin * (training.max - training.min);
  r.min = training.min - pad;
  r.max = training.max + pad;
  if (Features::on_log_scale(training.name) && training.min > 0.0) {
    r.min = training.min * std::pow(training.max / training.min, -margin);
  }
  return r;
}


namespace {

FeatureVector feature_vector(const std::vector<FeatureRange>& ranges, double margin, const Features& f) {
  FeatureVector out;
  out.x.resize(ranges.size());
  for (std::size_t j = 0; j < ranges.size(); ++j) {
    const auto v = f.value(ranges[j].name);
    if (!v) {
      out.status = CorrectionStatus::missing_feature;
      out.message = fmt::format("the model takes the record's {} as a feature, and it is not known for this row; give it "
                                "({})",
                                ranges[j].name, how_to_give(ranges[j].name));
      return out;
    }
    out.x[j] = *v;
  }
  for (std::size_t j = 0; j < ranges.size(); ++j) {
    const auto& r = ranges[j];
    const auto accepted = accepted_range(r, margin);
    if (r.name == "duration" && out.x[j] > accepted.max) {
      out.notes.push_back(fmt::format("duration {} s is beyond the training range ({}): corrected as {:.4g} s",
                                      fmt::format("{:.4g}", out.x[j]), feature_range_text(r.name, r.min, r.max), r.max));
      out.x[j] = r.max;
    } else if (!(out.x[j] >= accepted.min && out.x[j] <= accepted.max)) {
      out.status = CorrectionStatus::outside_training_range;
      out.message = out_of_range_reason(r, out.x[j]);
      out.refused = &r;
      return out;
    }
  }
  return out;
}


// A shift of a quantity's target from the measurement, in words: "+136 %"
// for a ratio, "+0.45" (Tu) or "+1.2 m/s" otherwise.
std::string shift_text(TargetForm form, double shift, std::string_view unit) {
  if (form == TargetForm::ratio) {
    const double percent = 100.0 * shift;
    return std::fabs(percent) >= 100.0 ? fmt::format("{:+.0f} %", percent) : fmt::format("{:+.3g} %", percent);
  }
  return unit.empty() ? fmt::format("{:+.3g}", shift) : fmt::format("{:+.3g} {}", shift, unit);
}

// One corrected quantity, the forest's distribution at the row and what the
// trust rules need to say about it.
struct Quantity {
  const char* forest;      // "AWCC forest's", "FSCC forest's"
  const char* name;        // "velocity", "Tu"
  const char* unit;        // "m/s", "" (dimensionless)
  const char* source;      // "AWCC's", "FSCC's"
  TargetForm form;
  double measured;
  bool nonnegative;
};

std::string value_text(const Quantity& q, double v) {
  return *q.unit ? fmt::format("{:.3g} {}", v, q.unit) : fmt::format("{:.3g}", v);
}

// Rule (a) and rule (b) of the trust rules (the model's header) for one
// quantity: the reasons it breaks, empty when it holds. `envelope_runs`
// says where the envelope was measured.
// What the trust rules find, rule by rule, each quantity's clause apart so
// that a rule both quantities break is named once.
struct Verdict {
  std::vector<std::string> envelope, modes, lag, yield;
  void add(const Verdict& v) {
    envelope.insert(envelope.end(), v.envelope.begin(), v.envelope.end());
    modes.insert(modes.end(), v.modes.begin(), v.modes.end());
    lag.insert(lag.end(), v.lag.begin(), v.lag.end());
    yield.insert(yield.end(), v.yield.begin(), v.yield.end());
  }
};

// Rule (d) (the model's header): AWCC's data yield; silent when the windows
// are not known.
Verdict chance_yield(const Features& f) {
  Verdict verdict;
  if (f.windows_accepted < 0 || f.windows_total <= 0) return verdict;
  const double yield = static_cast<double>(f.windows_accepted) / static_cast<double>(f.windows_total);
  if (yield >= awcc::chance_data_yield) return verdict;
  verdict.yield.push_back(fmt::format(
      "AWCC accepted {} of {} windows ({:.3g} %, below {:g} %), about what signals that share no bubble give by "
      "chance, so the measurement corrected may be chance peaks rather than the flow's",
      f.windows_accepted, f.windows_total, 100.0 * yield, 100.0 * awcc::chance_data_yield));
  return verdict;
}

// Rule (c) (the model's header): the measurement's lag in samples, from
// `source`'s velocity; silent when fs is not known.
Verdict unresolved_lag(const char* source, double velocity, double dx, double fs) {
  Verdict verdict;
  if (!(fs > 0.0) || !(dx > 0.0) || !(velocity > 0.0)) return verdict;
  const double lag = dx * fs / velocity;
  if (lag >= awcc::least_resolved_lag_samples) return verdict;
  const auto [lo, hi] = awcc::one_sample_velocity_bounds(dx, fs);
  verdict.lag.push_back(fmt::format(
      "{} velocity {:.3g} m/s is a lag of {:.2f} samples (dx fs / u, below {:g}), and every delay of 0.5-1.5 samples "
      "reads as one, so the record bounds the velocity ({:.4g}-{:.4g} m/s) and no forest's median measures it "
      "(sample faster or move the tips apart)",
      source, velocity, lag, awcc::least_resolved_lag_samples, lo, hi));
  return verdict;
}

// Rule (e) (the model's header): Tu of bubbles far larger than the tip
// separation; silent when d32 or dx is not known.
void judge_turbulence(Correction& c, const Features& f) {
  if (!c.turbulence_intensity || !(f.d32 > 0.0) || !(f.dx > 0.0)) return;
  const double ratio = f.d32 / f.dx;
  if (ratio <= largest_tu_size_ratio) return;
  c.large_bubbles = true;
  c.turbulence_message = fmt::format(
      "Tu not corrected: the Sauter diameter d32 {:.4g} mm is {:.3g} times the tip separation dx {:.4g} mm (above "
      "{:g}), so the tips meet each interface almost together and a window's delay follows the interface's tilt "
      "more than the flow; AWCC's Tu reads high there by more than the forest corrects, and its intervals do not "
      "hold (the quantiles are kept, the median is not a corrected value; move the tips apart to measure Tu)",
      1e3 * f.d32, ratio, 1e3 * f.dx, largest_tu_size_ratio);
}

Verdict untrusted_reasons(const Quantity& q, const WeightedDistribution& d,
                          const std::optional<std::array<double, 2>>& envelope, const std::string& envelope_runs) {
  Verdict verdict;
  const double identity = to_target(q.form, q.measured, q.measured);
  const double shift = d.quantile(0.5) - identity;
  if (envelope && !(shift >= -(*envelope)[0] && shift <= (*envelope)[1])) {
    const double median = from_target(q.form, d.quantile(0.5), q.measured);
    verdict.envelope.push_back(fmt::format(
        "the {} {} median {} is {} from {} {}; on {} the truth lay within {} to {} of the measurement for {:g} % of "
        "them",
        q.forest, q.name, value_text(q, q.nonnegative ? std::max(0.0, median) : median), shift_text(q.form, shift, q.unit),
        q.source, value_text(q, q.measured), envelope_runs, shift_text(q.form, -(*envelope)[0], q.unit),
        shift_text(q.form, (*envelope)[1], q.unit), 100.0 * envelope_coverage));
  }
  const bool log_scale = q.form == TargetForm::ratio && !d.values.empty() && d.values.front() > 0.0;
  const auto m = dip(d, log_scale);
  if (m.ratio < multimodal_dip_limit) {
    const auto lo = from_target(q.form, m.quantiles[m.interval], q.measured);
    const auto hi = from_target(q.form, m.quantiles[m.interval + 1], q.measured);
    const std::string range = *q.unit ? fmt::format("{:.3g}-{:.3g} {}", lo, hi, q.unit) : fmt::format("{:.3g}-{:.3g}", lo, hi);
    verdict.modes.push_back(fmt::format(
        "the {} {} distribution is {:.2f} times as dense between its {:g} and {:g} quantiles ({}) as in the densest "
        "interval on each side (one mode gives at least 1; the limit is {:g})",
        q.forest, q.name, m.ratio, modality_levels[m.interval], modality_levels[m.interval + 1], range,
        multimodal_dip_limit));
  }
  return verdict;
}

CorrectedQuantity corrected_quantity(const Quantity& q, const std::vector<double>& t) {
  CorrectedQuantity c;
  c.measured = q.measured;
  for (std::size_t k = 0; k < t.size(); ++k) {
    c.quantiles[k] = from_target(q.form, t[k], q.measured);
    if (q.nonnegative) c.quantiles[k] = std::max(0.0, c.quantiles[k]);
  }
  return c;
}

std::vector<double> quantiles_of(const WeightedDistribution& d) {
  std::vector<double> t;
  for (double a : correction_levels) t.push_back(d.quantile(a));
  return t;
}

// The trust rules' verdict on a correction (the model's header): each rule
// named once, with the clauses of the quantities that break it.
void judge(Correction& c, const Verdict& v) {
  c.outside_envelope = !v.envelope.empty();
  c.multimodal = !v.modes.empty();
  c.one_sample_lag = !v.lag.empty();
  c.chance_yield = !v.yield.empty();
  if (!c.outside_envelope && !c.multimodal && !c.one_sample_lag && !c.chance_yield) return;
  c.status = CorrectionStatus::untrusted;
  std::vector<std::string> rules;
  if (c.chance_yield) rules.push_back(fmt::format("a chance yield: {}", fmt::join(v.yield, "; ")));
  if (c.one_sample_lag) rules.push_back(fmt::format("a lag of one sample: {}", fmt::join(v.lag, "; ")));
  if (c.outside_envelope) rules.push_back(fmt::format("outside the envelope: {}", fmt::join(v.envelope, "; ")));
  if (c.multimodal) rules.push_back(fmt::format("multimodal: {}", fmt::join(v.modes, "; ")));
  c.message = fmt::format("{}", fmt::join(rules, "; "));
}

// A forest's envelope when the file stores none: its training targets'
// shifts from the measurement, pooled (the model's header). None for the
// value form, whose shift needs the measurement the targets do not keep.
std::vector<std::array<double, 2>> training_envelope(const QuantileForest& forest, TargetForm form) {
  if (form == TargetForm::value || forest.target_count() == 0) return {};
  const double identity = form == TargetForm::ratio ? 1.0 : 0.0;
  auto shifts = forest.targets();
  for (double& t : shifts) t -= identity;
  const auto e = envelope_of(std::move(shifts));
  if (!e) return {};
  return {*e};
}

}  // namespace

std::string Correction::why_not() const {
  if (corrected()) return {};
  return status == CorrectionStatus::untrusted ? "untrusted: " + message : message;
}

namespace {

// A forest's correction of a row, and the feature that kept it from the row
// (to say once what both forests refuse).
struct Attempt {
  Correction correction;
  const FeatureRange* refused = nullptr;
  double value = 0.0;
};

Attempt refused(const FeatureVector& x, const Features& f) {
  Attempt a{not_corrected(x.status, x.message), x.refused, 0.0};
  if (x.refused) a.value = f.value(x.refused->name).value_or(0.0);
  return a;
}

Attempt awcc_attempt(const CorrectionModel& m, const Features& f);

// A row without the record's features, by the reduced model (its forest named).
Attempt reduced_attempt(const CorrectionModel& m, const Features& f) {
  std::vector<std::string> missing;
  for (const auto& r : m.ranges)
    if (!f.value(r.name) && r.name != Features::weighting_name) missing.push_back(r.name);
  Attempt a = awcc_attempt(*m.reduced, f);
  auto& c = a.correction;
  if (c.velocity) {
    c.forest = "awcc-reduced";
    // A file of an earlier pdp lacks only the time scale: the recording,
    // processed again, gives it and the full forest.
    const bool only_scale = missing.size() == 1 && missing.front() == Features::scale_name;
    c.notes.insert(c.notes.begin(),
                   fmt::format("{} not known for this row: corrected by the reduced forest (u, Tu, c, d32, dx, dy, "
                               "Np), trained over every record length and rate, whose intervals are wider{}",
                               fmt::join(missing, ", "),
                               only_scale ? " (pdp process writes it as awcc.time_scale_ratio: process the "
                                            "recording again for the full forest)"
                                          : ""));
  }
  return a;
}

Attempt awcc_attempt(const CorrectionModel& m, const Features& f) {
  if (f.windows_accepted >= 0 && f.windows_accepted < m.min_windows) {
    return {not_corrected(CorrectionStatus::too_few_windows,
                          fmt::format("{} accepted windows; the model was trained on runs with at least {}",
                                      f.windows_accepted, m.min_windows))};
  }
  // A row whose weighting is not known, for a model that takes it: both
  // answers, equally weighted (correction/features.hpp).
  const bool mixed = m.takes_weighting() && f.awcc_unweighted < 0;
  Features known = f;
  if (mixed) known.awcc_unweighted = 0;
  const auto x = feature_vector(m.ranges, m.range_margin, known);
  if (x.status == CorrectionStatus::missing_feature && m.reduced) return reduced_attempt(m, f);
  if (!x.ok()) return refused(x, f);
  const auto& cal = m.calibration;
  auto velocity_d = m.velocity.distribution(x.x);
  auto tu_d = m.turbulence_intensity.distribution(x.x);
  if (mixed) {
    auto other = x.x;
    other[m.weighting_feature()] = 1.0;
    velocity_d = mixture(velocity_d, m.velocity.distribution(other));
    tu_d = mixture(tu_d, m.turbulence_intensity.distribution(other));
  }
  auto velocity_t = quantiles_of(velocity_d);
  auto tu_t = quantiles_of(tu_d);
  // The group's Tu band: the Tu forest's own median, before calibration.
  const double tu_median = from_target(m.turbulence_form, tu_t[median_level], f.turbulence_intensity);
  if (!cal.empty()) {
    Calibration::apply(cal.offsets(cal.velocity, f.windows_accepted, tu_median), velocity_t);
    Calibration::apply(cal.offsets(cal.turbulence_intensity, f.windows_accepted, tu_median), tu_t);
  }
  const Quantity u{"AWCC forest's", "velocity", "m/s", "AWCC's", m.velocity_form, f.velocity, false};
  const Quantity tu{"AWCC forest's", "Tu", "", "AWCC's", m.turbulence_form, f.turbulence_intensity, true};
  Correction c;
  c.status = CorrectionStatus::corrected;
  c.forest = "awcc";
  c.velocity = corrected_quantity(u, velocity_t);
  c.turbulence_intensity = corrected_quantity(tu, tu_t);
  c.notes = x.notes;
  if (mixed) {
    c.notes.push_back("how AWCC's moments were taken is not known for this row: the answers for duration-weighted "
                      "and unweighted moments are mixed, equally weighted (state it: the setting weighting)");
  }
  const std::string runs = cal.envelope_from_training
                               ? "the forest's training runs"
                               : fmt::format("runs the model was not trained on ({})",
                                             cal.group_text(f.windows_accepted, tu_median));
  auto verdict =
      untrusted_reasons(u, velocity_d, cal.envelope(cal.velocity_envelope, f.windows_accepted, tu_median), runs);
  verdict.add(untrusted_reasons(tu, tu_d, cal.envelope(cal.turbulence_envelope, f.windows_accepted, tu_median), runs));
  verdict.add(unresolved_lag("AWCC's", f.velocity, f.dx, f.fs));
  verdict.add(chance_yield(f));
  judge(c, verdict);
  judge_turbulence(c, f);
  return {c};
}

Attempt fscc_attempt(const CorrectionModel& m, const Features& f) {
  if (!m.fscc) return {not_corrected(CorrectionStatus::no_awcc_velocity, "the model has no FSCC forest")};
  if (const auto why = fscc_unusable(f); !why.empty()) return {not_corrected(CorrectionStatus::no_awcc_velocity, why)};
  const auto& forest = *m.fscc;
  const auto x = feature_vector(forest.ranges, m.range_margin, f);
  if (!x.ok()) return refused(x, f);
  const auto d = forest.velocity.distribution(x.x);
  auto t = quantiles_of(d);
  const auto& cal = forest.calibration;
  if (!cal.empty()) Calibration::apply(cal.velocity.front(), t);
  const Quantity u{"FSCC forest's", "velocity", "m/s", "FSCC's", forest.form, f.fscc_velocity, false};
  Correction c;
  c.status = CorrectionStatus::corrected;
  c.forest = "fscc";
  c.velocity = corrected_quantity(u, t);
  c.notes = x.notes;
  auto verdict = untrusted_reasons(u, d, cal.envelope(cal.velocity_envelope, -1, 0.0),
                                   cal.envelope_from_training ? "the FSCC forest's training runs"
                                                              : "the FSCC forest's calibration runs");
  verdict.add(unresolved_lag("FSCC's", f.fscc_velocity, f.dx, f.fs));
  judge(c, verdict);
  return {c};
}

// The FSCC forest's answer when the AWCC forest's is not a correction: its
// correction or its untrusted quantiles, else AWCC's status with both
// reasons, each said once (a feature both forests refuse is named once).
Correction after_awcc(const Attempt& first, const Attempt& fscc) {
  const auto& c = fscc.correction;
  if (c.corrected() || c.status == CorrectionStatus::untrusted) {
    // Why the AWCC forest did not answer, first: a row the AWCC forest
    // refuses for a feature (a dx or fs typed wrong puts the lag outside its
    // range) is corrected from FSCC's velocity, and says so.
    Correction out = c;
    out.notes.insert(out.notes.begin(),
                     fmt::format("AWCC forest: {}; corrected from FSCC's velocity by the FSCC forest, which gives no Tu",
                                 first.correction.message));
    return out;
  }
  Correction awcc = first.correction;
  const auto* a = first.refused;
  const auto* b = fscc.refused;
  if (a && b && a->name == b->name) {
    awcc.message = fmt::format("{} is outside the training ranges of both forests (AWCC forest {}, FSCC forest {}){}",
                               feature_value_text(a->name, first.value), feature_range_text(a->name, a->min, a->max),
                               feature_range_text(b->name, b->min, b->max), out_of_range_meaning(*a, first.value));
  } else {
    awcc.message = fmt::format("{}; FSCC forest: {}", awcc.message, c.message);
  }
  return awcc;
}

}  // namespace

Correction CorrectionModel::correct(const Features& f) const { return awcc_attempt(*this, f).correction; }

namespace {

// AWCC statuses after which the FSCC forest may correct the velocity.
bool fscc_may_follow(CorrectionStatus s) {
  switch (s) {
    case CorrectionStatus::awcc_not_run:
    case CorrectionStatus::no_awcc_velocity:
    case CorrectionStatus::too_few_windows:
    case CorrectionStatus::awcc_not_measured:
    case CorrectionStatus::outside_training_range: return true;
    default: return false;
  }
}

}  // namespace

bool CorrectionModel::falls_back_to_fscc(CorrectionStatus awcc_status) const {
  return fscc.has_value() && fscc_may_follow(awcc_status);
}

Correction CorrectionModel::correct_fscc(const Features& f) const { return fscc_attempt(*this, f).correction; }

Correction CorrectionModel::correct(const Measurement& m) const {
  const auto f = make_features(m);
  const Attempt awcc = f.ok() ? awcc_attempt(*this, f.features) : Attempt{not_corrected(f.status, f.message)};
  if (awcc.correction.corrected() || !fscc || !fscc_may_follow(awcc.correction.status)) return awcc.correction;
  return after_awcc(awcc, fscc_attempt(*this, f.features));
}

Correction CorrectionModel::correct(const MeasurementResult& m) const {
  if (m.status == CorrectionStatus::corrected) return correct(m.measurement);
  const Attempt awcc{not_corrected(m.status, m.message)};
  if (!fscc || !fscc_may_follow(m.status)) return awcc.correction;
  return after_awcc(awcc, fscc_attempt(*this, make_features(m.measurement).features));
}

void CorrectionModel::use_training_envelopes() {
  if (calibration.velocity_envelope.empty()) {
    calibration.velocity_envelope = training_envelope(velocity, velocity_form);
    calibration.turbulence_envelope = training_envelope(turbulence_intensity, turbulence_form);
    calibration.envelope_from_training = true;
  }
  if (fscc && fscc->calibration.velocity_envelope.empty()) {
    fscc->calibration.velocity_envelope = training_envelope(fscc->velocity, fscc->form);
    fscc->calibration.envelope_from_training = true;
  }
}

std::string CorrectionModel::mismatch(const Processing& results) const {
  Processing compared = results;
  if (takes_weighting()) compared.weighting = processing.weighting;  // a feature, not a mismatch
  return processing_mismatch(processing, compared);
}

std::size_t CorrectionModel::weighting_feature() const {
  for (std::size_t j = 0; j < ranges.size(); ++j)
    if (ranges[j].name == Features::weighting_name) return j;
  return ranges.size();
}

bool CorrectionModel::takes_weighting() const { return weighting_feature() < ranges.size(); }

}  // namespace correction
