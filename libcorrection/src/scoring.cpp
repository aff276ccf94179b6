// Scoring: a model's corrections of held-out runs against their truth, by
// band and against another model, and the reports and CSVs of the scores.

#include "correction/training.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <thread>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/order_statistics.hpp"
#include "awcc/parallel.hpp"
#include "awcc/random.hpp"
#include "awcc/units.hpp"
#include "awcc/version.hpp"
#include "correction/sweep_columns.hpp"
#include "training_steps.hpp"

namespace correction {

using namespace detail;

namespace {

// The statistics of one quantity (velocity or Tu) over the scored rows.
struct QuantityScores {
  double square_raw = 0.0, square_corrected = 0.0, sum_raw = 0.0, sum_corrected = 0.0;
  double pinball = 0.0, covered80 = 0.0, covered95 = 0.0;
  std::vector<double> abs_raw, abs_corrected, losses;

  void add(double raw_error, double corrected_error, double truth, const std::array<double, correction_levels.size()>& q, double loss) {
    square_raw += raw_error * raw_error;
    square_corrected += corrected_error * corrected_error;
    sum_raw += raw_error;
    sum_corrected += corrected_error;
    abs_raw.push_back(std::fabs(raw_error));
    abs_corrected.push_back(std::fabs(corrected_error));
    losses.push_back(loss);
    pinball += loss;
    covered80 += (truth >= q[lower_level(interval80)] && truth <= q[upper_level(interval80)]) ? 1.0 : 0.0;
    covered95 += (truth >= q[lower_level(interval95)] && truth <= q[upper_level(interval95)]) ? 1.0 : 0.0;
  }

  /// rmse, median |error|, mean error (raw, corrected), pinball, coverages.
  void finish(double& rmse_raw, double& rmse_corrected, double& median_raw, double& median_corrected,
              double& bias_raw, double& bias_corrected, double& mean_pinball, double& coverage80,
              double& coverage95, std::vector<double>& row_losses) {
    median_raw = awcc::median(abs_raw);
    median_corrected = awcc::median(abs_corrected);
    row_losses = std::move(losses);
    const auto n = static_cast<double>(abs_raw.size());
    if (n == 0) return;
    rmse_raw = std::sqrt(square_raw / n);
    rmse_corrected = std::sqrt(square_corrected / n);
    bias_raw = sum_raw / n;
    bias_corrected = sum_corrected / n;
    mean_pinball = pinball / n;
    coverage80 = covered80 / n;
    coverage95 = covered95 / n;
  }
};

}  // namespace

HeldOutScores score(const CorrectionModel& model, const std::vector<TrainingRow>& rows,
                    std::vector<HeldOutPrediction>* predictions, int threads) {
  std::vector<Correction> c(rows.size());
  parallel_for(rows.size(), threads, [&](std::size_t i) { c[i] = model.correct(rows[i].features); });
  HeldOutScores s;
  QuantityScores velocity, tu;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    if (predictions) predictions->push_back({r, c[i]});
    if (!c[i].velocity || !c[i].turbulence_intensity) {
      ++s.out_of_range;
      continue;
    }
    ++s.rows;
    s.untrusted += c[i].status == CorrectionStatus::untrusted;
    s.outside_envelope += c[i].outside_envelope;
    s.multimodal += c[i].multimodal;
    s.one_sample_lag += c[i].one_sample_lag;
    s.chance_yield += c[i].chance_yield;
    s.large_bubbles += c[i].large_bubbles;
    const auto& u = *c[i].velocity;
    const auto& t = *c[i].turbulence_intensity;
    const std::vector<double> uq(u.quantiles.begin(), u.quantiles.end()), tq(t.quantiles.begin(), t.quantiles.end());
    // Velocity relative to the truth, Tu absolute.
    velocity.add(r.features.velocity / r.true_velocity - 1.0, u.median() / r.true_velocity - 1.0, r.true_velocity,
                 u.quantiles, target_pinball(uq, r, true));
    tu.add(r.features.turbulence_intensity - r.true_turbulence_intensity, t.median() - r.true_turbulence_intensity,
           r.true_turbulence_intensity, t.quantiles, target_pinball(tq, r, false));
  }
  velocity.finish(s.velocity_rmse_raw, s.velocity_rmse_corrected, s.velocity_median_abs_raw,
                  s.velocity_median_abs_corrected, s.velocity_bias_raw, s.velocity_bias_corrected, s.velocity_pinball,
                  s.velocity_coverage80, s.velocity_coverage95, s.velocity_losses);
  tu.finish(s.tu_rmse_raw, s.tu_rmse_corrected, s.tu_median_abs_raw, s.tu_median_abs_corrected, s.tu_bias_raw,
            s.tu_bias_corrected, s.tu_pinball, s.tu_coverage80, s.tu_coverage95, s.tu_losses);
  return s;
}

namespace detail {

// The FSCC forest's scores on held-out rows (all with an FSCC velocity, or
// those AWCC cannot serve: where the forest is applied).
FsccScores score_fscc(const CorrectionModel& scorer, const std::vector<TrainingRow>& held_out, bool unserved_only) {
  FsccScores sc;
  std::vector<double> abs_raw, abs_corrected;
  double sq_raw = 0.0, sq_corrected = 0.0;
  for (const auto& r : held_out) {
    if (unserved_only && r.awcc_served) continue;
    const auto c = scorer.correct_fscc(r.features);
    if (!c.velocity) {
      ++sc.out_of_range;
      continue;
    }
    sc.untrusted += c.status == CorrectionStatus::untrusted;
    sc.outside_envelope += c.outside_envelope;
    sc.multimodal += c.multimodal;
    sc.one_sample_lag += c.one_sample_lag;
    const double raw = r.features.fscc_velocity / r.true_velocity - 1.0;
    const double corrected = c.velocity->median() / r.true_velocity - 1.0;
    sq_raw += raw * raw;
    sq_corrected += corrected * corrected;
    abs_raw.push_back(std::fabs(raw));
    abs_corrected.push_back(std::fabs(corrected));
    const auto& q = *c.velocity;
    sc.coverage80 += q.lower(interval80) <= r.true_velocity && r.true_velocity <= q.upper(interval80);
    sc.coverage95 += q.lower(interval95) <= r.true_velocity && r.true_velocity <= q.upper(interval95);
    ++sc.rows;
  }
  if (sc.rows > 0) {
    const auto n = static_cast<double>(sc.rows);
    sc.rmse_raw = std::sqrt(sq_raw / n);
    sc.rmse_corrected = std::sqrt(sq_corrected / n);
    sc.median_abs_raw = awcc::median(abs_raw);
    sc.median_abs_corrected = awcc::median(abs_corrected);
    sc.coverage80 /= n;
    sc.coverage95 /= n;
  }
  return sc;
}

}  // namespace detail

std::string scores_report(const HeldOutScores& h, const std::vector<HeldOutPrediction>& predictions) {
  std::string out;
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  line("                         raw AWCC    corrected median");
  line(fmt::format("  velocity RMSE          {:7.3f} %   {:7.3f} %", 100 * h.velocity_rmse_raw, 100 * h.velocity_rmse_corrected));
  line(fmt::format("  velocity median |err|  {:7.3f} %   {:7.3f} %", 100 * h.velocity_median_abs_raw,
                   100 * h.velocity_median_abs_corrected));
  line(fmt::format("  velocity mean error    {:7.3f} %   {:7.3f} %", 100 * h.velocity_bias_raw, 100 * h.velocity_bias_corrected));
  line(fmt::format("  Tu RMSE                {:7.4f}     {:7.4f}", h.tu_rmse_raw, h.tu_rmse_corrected));
  line(fmt::format("  Tu median |err|        {:7.4f}     {:7.4f}", h.tu_median_abs_raw, h.tu_median_abs_corrected));
  line(fmt::format("  Tu mean error          {:7.4f}     {:7.4f}", h.tu_bias_raw, h.tu_bias_corrected));
  line(fmt::format("  coverage 80 % / 95 %   velocity {:.1f} / {:.1f} %, Tu {:.1f} / {:.1f} %", 100 * h.velocity_coverage80,
                   100 * h.velocity_coverage95, 100 * h.tu_coverage80, 100 * h.tu_coverage95));
  const auto table = scores_by_band(predictions);
  if (!table.empty()) {
    line("Held-out runs by band: errors raw -> corrected (velocity relative, Tu absolute) and coverage (nominal 80 / 95 %):");
    line("  band                          runs  corrected   u RMSE raw -> corr    u median|err|      Tu RMSE        "
         "Tu median|err|    u 80 %  95 %   Tu 80 %  95 %");
    for (const auto& b : table) {
      line(fmt::format("  {:<28} {:>6} {:>9}   {:7.2f} -> {:6.2f} %   {:5.2f} -> {:5.2f} %   {:.4f} -> {:.4f}   "
                       "{:.4f} -> {:.4f}   {:5.1f} {:5.1f}   {:6.1f} {:5.1f}",
                       b.band, b.runs, b.rows, 100 * b.velocity_rmse_raw, 100 * b.velocity_rmse_corrected,
                       100 * b.velocity_median_abs_raw, 100 * b.velocity_median_abs_corrected, b.tu_rmse_raw,
                       b.tu_rmse_corrected, b.tu_median_abs_raw, b.tu_median_abs_corrected, 100 * b.velocity80,
                       100 * b.velocity95, 100 * b.tu80, 100 * b.tu95));
    }
  }
  return out;
}

std::string TrainResult::report() const {
  std::string out = model.provenance + "\n\n";
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  if (!cv.empty()) {
    line("Cross-validation (mean pinball loss over the correction levels; velocity relative to the truth):");
    line("  target                form        min_leaf  features/split  pinball");
    for (const auto& e : cv) {
      line(fmt::format("  {:<21} {:<11} {:>8}  {:>14}  {:.6f}", e.target, to_string(e.form), e.min_leaf,
                       e.features_per_split, e.pinball));
    }
    line(fmt::format("  ({:.1f} s)", seconds_cv));
  }
  const auto& h = held_out;
  line(fmt::format("Held out: {} runs ({} outside the training ranges, not scored; {} of the scored untrusted by the "
                   "trust rules: {} outside the envelope, {} multimodal, {} at a lag of one sample, {} at a chance "
                   "yield); training {} runs in {:.2f} s",
                   h.rows, h.out_of_range, h.untrusted, h.outside_envelope, h.multimodal, h.one_sample_lag,
                   h.chance_yield, training_rows, seconds_train));
  out += scores_report(h, predictions);
  if (model.reduced) {
    const auto& r = reduced_held_out;
    line(fmt::format("Reduced model (rows without fs, duration or windows: peers' files), on the same held-out runs "
                     "with those features removed: {} runs scored ({} outside the training ranges; {} untrusted)",
                     r.rows, r.out_of_range, r.untrusted));
    out += scores_report(r, reduced_predictions);
    line(fmt::format("  pinball loss: velocity {:.6f} (extended {:.6f}), Tu {:.6f} (extended {:.6f})",
                     r.velocity_pinball, h.velocity_pinball, r.tu_pinball, h.tu_pinball));
  }
  if (!learning_curve.empty()) {
    line("Learning curve (held-out scores against training runs):");
    line("  (gain: paired decrease of the pinball loss from the previous point, +/- its standard error)");
    line("  runs    velocity RMSE   velocity pinball (gain)              Tu RMSE   Tu pinball (gain)");
    for (const auto& p : learning_curve) {
      line(fmt::format("  {:>6}  {:9.3f} %   {:.6f} ({:+.6f} +/- {:.6f})   {:8.4f}   {:.6f} ({:+.6f} +/- {:.6f})",
                       p.training_rows, 100 * p.scores.velocity_rmse_corrected, p.scores.velocity_pinball,
                       p.velocity_gain, p.velocity_gain_se, p.scores.tu_rmse_corrected, p.scores.tu_pinball, p.tu_gain,
                       p.tu_gain_se));
    }
  }
  return out;
}

namespace {

struct Band {
  std::string name;
  std::function<bool(const HeldOutPrediction&)> holds;
};

// The bands of the held-out tables: true Tu (the bands, and the
// campaign's top, 0.35-0.45, apart: a band at the edge of the drawn range is
// where quantile forests cover worst), the model's Tu, accepted windows,
// sampling rate. Plain copies of the ends: lambdas capture them (clang 14
// cannot capture bindings).
std::vector<Band> held_out_bands() {
  std::vector<Band> bands{{"all", [](const HeldOutPrediction&) { return true; }}};
  for (const auto& band : std::vector<std::pair<double, double>>{{0, 0.1}, {0.1, 0.2}, {0.2, 0.3}, {0.3, 0.35}, {0.35, 0.45}}) {
    const double lo = band.first, hi = band.second;
    bands.push_back({fmt::format("true Tu {:g}-{:g}", lo, hi), [lo, hi](const HeldOutPrediction& p) {
                       return p.row.true_turbulence_intensity >= lo && p.row.true_turbulence_intensity < hi;
                     }});
  }
  // The model's Tu (its corrected median): what a lab sees, and what the
  // calibration's Tu bands are made of.
  for (const auto& band : std::vector<std::pair<double, double>>{{0, 0.1}, {0.1, 0.2}, {0.2, 0.3}, {0.3, 1e300}}) {
    const double lo = band.first, hi = band.second;
    bands.push_back({hi > 1e299 ? fmt::format("model Tu {:g}+", lo) : fmt::format("model Tu {:g}-{:g}", lo, hi),
                     [lo, hi](const HeldOutPrediction& p) {
                       if (!p.correction.turbulence_intensity) return false;
                       const double t = p.correction.turbulence_intensity->median();
                       return t >= lo && t < hi;
                     }});
  }
  for (const auto& band : std::vector<std::pair<std::int64_t, std::int64_t>>{{10, 30}, {30, 100}, {100, 1LL << 62}}) {
    const std::int64_t lo = band.first, hi = band.second;
    bands.push_back({hi > (1LL << 61) ? fmt::format("windows {}+", lo) : fmt::format("windows {}-{}", lo, hi - 1),
                     [lo, hi](const HeldOutPrediction& p) {
                       return p.row.features.windows_accepted >= lo && p.row.features.windows_accepted < hi;
                     }});
  }
  for (const auto& band : std::vector<std::pair<double, double>>{{0, 50e3}, {50e3, 200e3}, {200e3, 1e300}}) {
    const double lo = band.first, hi = band.second;
    bands.push_back({hi > 1e299 ? fmt::format("fs {:g} kHz+", lo / 1e3) : fmt::format("fs {:g}-{:g} kHz", lo / 1e3, hi / 1e3),
                     [lo, hi](const HeldOutPrediction& p) { return p.row.features.fs > lo && p.row.features.fs <= hi; }});
  }
  // The record's length (issue 33: the coverage by duration, to 1,800 s and
  // beyond the training records, where the duration is held).
  for (const auto& band : std::vector<std::pair<double, double>>{{0, 60}, {60, 300}, {300, 600}, {600, 1800}, {1800, 1e300}}) {
    const double lo = band.first, hi = band.second;
    bands.push_back({hi > 1e299 ? fmt::format("duration {:g} s+", lo) : fmt::format("duration {:g}-{:g} s", lo, hi),
                     [lo, hi](const HeldOutPrediction& p) {
                       return p.row.features.duration > lo && p.row.features.duration <= hi;
                     }});
  }
  // How AWCC's moments were taken (a model with the weighting feature
  // scores each run both ways).
  for (const int unweighted : {0, 1}) {
    bands.push_back({unweighted ? "unweighted moments" : "duration-weighted moments",
                     [unweighted](const HeldOutPrediction& p) { return p.row.features.awcc_unweighted == unweighted; }});
  }
  return bands;
}

}  // namespace

std::vector<BandScores> scores_by_band(const std::vector<HeldOutPrediction>& predictions) {
  std::vector<BandScores> out;
  for (const auto& b : held_out_bands()) {
    BandScores c;
    c.band = b.name;
    std::vector<double> u_raw, u_corrected, t_raw, t_corrected;
    double u_sq_raw = 0.0, u_sq_corrected = 0.0, t_sq_raw = 0.0, t_sq_corrected = 0.0;
    for (const auto& p : predictions) {
      if (!b.holds(p)) continue;
      ++c.runs;
      if (!p.correction.velocity || !p.correction.turbulence_intensity) continue;  // untrusted rows scored too
      const auto& u = *p.correction.velocity;
      const auto& t = *p.correction.turbulence_intensity;
      const double uu = p.row.true_velocity, tt = p.row.true_turbulence_intensity;
      const double ur = p.row.features.velocity / uu - 1.0, uc = p.correction.velocity->median() / uu - 1.0;
      const double tr = p.row.features.turbulence_intensity - tt, tc = p.correction.turbulence_intensity->median() - tt;
      u_sq_raw += ur * ur, u_sq_corrected += uc * uc, t_sq_raw += tr * tr, t_sq_corrected += tc * tc;
      u_raw.push_back(std::fabs(ur)), u_corrected.push_back(std::fabs(uc));
      t_raw.push_back(std::fabs(tr)), t_corrected.push_back(std::fabs(tc));
      c.velocity80 += u.lower(interval80) <= uu && uu <= u.upper(interval80);
      c.velocity95 += u.lower(interval95) <= uu && uu <= u.upper(interval95);
      c.tu80 += t.lower(interval80) <= tt && tt <= t.upper(interval80);
      c.tu95 += t.lower(interval95) <= tt && tt <= t.upper(interval95);
      ++c.rows;
    }
    if (c.rows == 0) continue;  // a band the runs do not reach (fs bands of a 500 kHz campaign)
    const auto n = static_cast<double>(c.rows);
    c.velocity80 /= n, c.velocity95 /= n, c.tu80 /= n, c.tu95 /= n;
    c.velocity_rmse_raw = std::sqrt(u_sq_raw / n);
    c.velocity_rmse_corrected = std::sqrt(u_sq_corrected / n);
    c.tu_rmse_raw = std::sqrt(t_sq_raw / n);
    c.tu_rmse_corrected = std::sqrt(t_sq_corrected / n);
    c.velocity_median_abs_raw = awcc::median(u_raw);
    c.velocity_median_abs_corrected = awcc::median(u_corrected);
    c.tu_median_abs_raw = awcc::median(t_raw);
    c.tu_median_abs_corrected = awcc::median(t_corrected);
    out.push_back(c);
  }
  return out;
}

std::vector<HeldOutPrediction> corrected_by_both(const std::vector<HeldOutPrediction>& predictions,
                                                 const std::vector<HeldOutPrediction>& other) {
  if (predictions.size() != other.size()) {
    throw std::invalid_argument("corrected_by_both: the two prediction sets are not of the same runs");
  }
  std::vector<HeldOutPrediction> out;
  for (std::size_t i = 0; i < predictions.size(); ++i) {
    if (predictions[i].row.run != other[i].row.run || predictions[i].row.study != other[i].row.study) {
      throw std::invalid_argument("corrected_by_both: the two prediction sets are not of the same runs");
    }
    if (predictions[i].correction.velocity && other[i].correction.velocity) out.push_back(predictions[i]);
  }
  return out;
}

std::string comparison_report(const std::vector<HeldOutPrediction>& mine, const std::vector<HeldOutPrediction>& other,
                              const std::string& other_name) {
  const auto all = scores_by_band(mine);
  const auto theirs = scores_by_band(other);
  const auto both_mine = scores_by_band(corrected_by_both(mine, other));
  const auto both_theirs = scores_by_band(corrected_by_both(other, mine));
  auto find = [](const std::vector<BandScores>& t, const std::string& band) -> const BandScores* {
    for (const auto& b : t)
      if (b.band == band) return &b;
    return nullptr;
  };
  std::string out = fmt::format(
      "Against {} on the same held-out runs: errors on the runs both models correct (raw = AWCC's; velocity "
      "relative, Tu absolute):\n"
      "  band                          runs  corrected: this  other   u RMSE raw / other / this   "
      "u median|err| raw / other / this   Tu RMSE raw / other / this   Tu median|err| raw / other / this\n",
      other_name);
  std::string coverage =
      "Coverage on the same runs (nominal 80 / 95 %), other / this:\n"
      "  band                          both     u 80 %         u 95 %         Tu 80 %        Tu 95 %\n";
  for (const auto& a : all) {
    // Each model reads its own Tu, so a band of it would hold other runs for
    // each: bands of the model's Tu are left out of the comparison.
    if (a.band.starts_with("model Tu")) continue;
    const auto* t = find(theirs, a.band);
    const auto* bm = find(both_mine, a.band);
    const auto* bt = find(both_theirs, a.band);
    out += fmt::format("  {:<28} {:>6} {:>16} {:>6}", a.band, a.runs, a.rows, t ? t->rows : 0);
    if (bm && bt) {
      out += fmt::format("   {:6.2f} / {:6.2f} / {:6.2f} %   {:6.2f} / {:6.2f} / {:6.2f} %       "
                         "{:.4f} / {:.4f} / {:.4f}   {:.4f} / {:.4f} / {:.4f}",
                         100 * bt->velocity_rmse_raw, 100 * bt->velocity_rmse_corrected,
                         100 * bm->velocity_rmse_corrected, 100 * bt->velocity_median_abs_raw,
                         100 * bt->velocity_median_abs_corrected, 100 * bm->velocity_median_abs_corrected,
                         bt->tu_rmse_raw, bt->tu_rmse_corrected, bm->tu_rmse_corrected, bt->tu_median_abs_raw,
                         bt->tu_median_abs_corrected, bm->tu_median_abs_corrected);
      coverage += fmt::format("  {:<28} {:>6}   {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}  {:5.1f} / {:5.1f}\n",
                              a.band, bm->rows, 100 * bt->velocity80, 100 * bm->velocity80, 100 * bt->velocity95,
                              100 * bm->velocity95, 100 * bt->tu80, 100 * bm->tu80, 100 * bt->tu95, 100 * bm->tu95);
    }
    out += "\n";
  }
  return out + coverage;
}

std::string predictions_csv(const std::vector<HeldOutPrediction>& predictions) {
  std::string out = "run,velocity,turbulence_intensity,void_fraction,d32,dx,dy,np,windows_accepted,fs,duration,"
                    "awcc_unweighted,true_velocity,true_turbulence_intensity,in_range,status,turbulence_corrected";
  for (const char* q : {"velocity", "turbulence_intensity"}) {
    for (const char* l : correction_level_names) out += fmt::format(",corrected_{}_q{}", q, l);
  }
  out += "\n";
  for (const auto& p : predictions) {
    const auto& f = p.row.features;
    out += fmt::format("{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{},{:.10g},{:.10g},{},{:.10g},{:.10g},{},{},{}",
                       p.row.run, f.velocity, f.turbulence_intensity, f.void_fraction, f.d32, f.dx, f.dy, f.np,
                       f.windows_accepted, f.fs, f.duration, f.awcc_unweighted, p.row.true_velocity,
                       p.row.true_turbulence_intensity,
                       p.correction.corrected() ? 1 : 0, to_string(p.correction.status),
                       p.correction.turbulence_corrected() ? 1 : 0);
    for (const auto* q : {&p.correction.velocity, &p.correction.turbulence_intensity}) {
      for (std::size_t k = 0; k < correction_levels.size(); ++k) {
        out += *q ? fmt::format(",{:.10g}", (*q)->quantiles[k]) : std::string(",");
      }
    }
    out += "\n";
  }
  return out;
}

std::string learning_curve_csv(const std::vector<LearningPoint>& curve) {
  std::string out = "training_runs,held_out_runs,velocity_rmse_raw,velocity_rmse_corrected,velocity_pinball,"
                    "velocity_coverage80,velocity_coverage95,tu_rmse_raw,tu_rmse_corrected,tu_pinball,tu_coverage80,"
                    "tu_coverage95,velocity_gain,velocity_gain_se,tu_gain,tu_gain_se\n";
  for (const auto& p : curve) {
    const auto& s = p.scores;
    out += fmt::format("{},{},{:.8g},{:.8g},{:.8g},{:.6g},{:.6g},{:.8g},{:.8g},{:.8g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n",
                       p.training_rows, s.rows, s.velocity_rmse_raw, s.velocity_rmse_corrected, s.velocity_pinball,
                       s.velocity_coverage80, s.velocity_coverage95, s.tu_rmse_raw, s.tu_rmse_corrected, s.tu_pinball,
                       s.tu_coverage80, s.tu_coverage95, p.velocity_gain, p.velocity_gain_se, p.tu_gain, p.tu_gain_se);
  }
  return out;
}

}  // namespace correction
