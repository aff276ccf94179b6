// Calibration (model.hpp, Calibration): the conformal offsets and envelopes
// measured on a model's calibration runs, and how a row's group applies them.

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
#include "correction/model.hpp"

namespace correction {

using namespace detail;

namespace detail {

// Q = E_k, k = ceil((n + 1)(1 - alpha)) of the scores (model.hpp, Calibration).
// With k > n the guarantee needs Q = infinity: too few runs, refused.
double conformal_offset(std::vector<double> e, double alpha) {
  std::sort(e.begin(), e.end());
  const auto n = static_cast<double>(e.size());
  const auto rank = static_cast<std::size_t>(std::ceil((n + 1.0) * (1.0 - alpha)));
  if (e.empty() || rank > e.size()) {
    throw awcc::OptionError(fmt::format("{} calibration runs cannot calibrate a {:g} % interval", e.size(),
                                        100 * (1 - alpha)),
                            "calibration");
  }
  return e[rank - 1];
}

IntervalOffsets interval_scores(const std::vector<double>& t, double target) {
  IntervalOffsets e{};
  for (std::size_t k = 0; k < interval_count; ++k) e[k] = std::max(t[lower_level(k)] - target, target - t[upper_level(k)]);
  return e;
}



// The envelopes of trust rule (a) (model.hpp) from rows' shifts {velocity,
// Tu} and their groups: the group's rows, else the window band's, else all
// of them; too few even then, the model's own (its training targets').
void set_envelopes(Calibration& c, const CorrectionModel& model, const std::vector<int>& band,
                   const std::vector<int>& tu_band, const std::vector<std::array<double, 2>>& shifts) {
  auto envelope = [&](const std::function<bool(std::size_t)>& in, std::size_t q) {
    std::vector<double> e;
    for (std::size_t i = 0; i < shifts.size(); ++i)
      if (in(i)) e.push_back(shifts[i][q]);
    return envelope_of(std::move(e));
  };
  c.velocity_envelope.clear();
  c.turbulence_envelope.clear();
  const std::function<bool(std::size_t)> all = [](std::size_t) { return true; };
  if (!envelope(all, 0) || !envelope(all, 1)) {
    c.velocity_envelope = model.calibration.velocity_envelope;
    c.turbulence_envelope = model.calibration.turbulence_envelope;
    c.envelope_from_training = model.calibration.envelope_from_training;
    return;
  }
  c.envelope_from_training = false;
  for (std::size_t b = 0; b <= c.window_edges.size(); ++b) {
    const int w = static_cast<int>(b);
    for (std::size_t h = 0; h < c.tu_bands(); ++h) {
      const std::function<bool(std::size_t)> in_group = [&band, &tu_band, w, h](std::size_t i) {
        return band[i] == w && tu_band[i] == static_cast<int>(h);
      };
      const std::function<bool(std::size_t)> in_band = [&band, w](std::size_t i) { return band[i] == w; };
      for (std::size_t q = 0; q < 2; ++q) {
        auto e = envelope(in_group, q);
        if (!e) e = envelope(in_band, q);
        if (!e) e = envelope(all, q);
        (q == 0 ? c.velocity_envelope : c.turbulence_envelope).push_back(*e);
      }
    }
  }
}

// The FSCC forest's envelope from rows' truths (its target's shift from FSCC's velocity).
std::vector<std::array<double, 2>> fscc_envelope(const FsccForest& f, const std::vector<TrainingRow>& rows) {
  std::vector<double> shifts;
  for (const auto& r : rows) {
    const double v = r.features.fscc_velocity;
    shifts.push_back(to_target(f.form, r.true_velocity, v) - to_target(f.form, v, v));
  }
  const auto e = envelope_of(std::move(shifts));
  return e ? std::vector<std::array<double, 2>>{*e} : std::vector<std::array<double, 2>>{};
}

}  // namespace detail

Calibration calibrate(const CorrectionModel& model, const std::vector<TrainingRow>& rows,
                      const std::vector<std::int64_t>& window_edges, int threads,
                      const std::vector<double>& tu_edges) {
  std::vector<std::string> names;
  for (const auto& r : model.ranges) names.push_back(r.name);
  Calibration c;
  c.window_edges = window_edges;
  c.tu_edges = tu_edges;
  // Scores of each row: velocity then Tu, each interval of
  // interval_coverages; its window band and Tu band (the Tu forest's
  // median, as correct() finds it).
  std::vector<std::array<double, 2 * interval_count>> scores(rows.size());
  std::vector<int> band(rows.size()), tu_band(rows.size());
  // The truth's shift from the measurement (model.hpp, trust rule (a)): velocity, Tu.
  std::vector<std::array<double, 2>> shifts(rows.size());
  parallel_for(rows.size(), threads, [&](std::size_t i) {
    const auto& r = rows[i];
    const auto x = vector_of(r.features, names);
    for (int f = 0; f < 2; ++f) {
      const auto& forest = f == 0 ? model.velocity : model.turbulence_intensity;
      const auto form = f == 0 ? model.velocity_form : model.turbulence_form;
      const double target = f == 0 ? to_target(form, r.true_velocity, r.features.velocity)
                                   : to_target(form, r.true_turbulence_intensity, r.features.turbulence_intensity);
      const auto t = forest.quantiles(x, correction_levels);
      const auto e = interval_scores(t, target);
      const double measured = f == 0 ? r.features.velocity : r.features.turbulence_intensity;
      shifts[i][static_cast<std::size_t>(f)] = target - to_target(form, measured, measured);
      for (std::size_t k = 0; k < interval_count; ++k) scores[i][interval_count * static_cast<std::size_t>(f) + k] = e[k];
      if (f == 1) tu_band[i] = c.tu_band(from_target(form, t[median_level], r.features.turbulence_intensity));
    }
    band[i] = c.band(r.features.windows_accepted);
  });
  // The offsets of the rows that `in` admits.
  auto offsets = [&](const std::function<bool(std::size_t)>& in, std::size_t column0) {
    IntervalOffsets q{};
    for (std::size_t k = 0; k < interval_count; ++k) {
      std::vector<double> e;
      for (std::size_t i = 0; i < rows.size(); ++i)
        if (in(i)) e.push_back(scores[i][column0 + k]);
      q[k] = conformal_offset(std::move(e), calibration_alpha[k]);
    }
    return q;
  };
  // A group with too few calibration runs (fewer than 1/alpha for the 95 %
  // interval, with margin) takes its window band's offsets; a window band
  // with too few, the pooled ones.
  constexpr std::int64_t least = 50;
  for (std::size_t b = 0; b <= window_edges.size(); ++b) {
    const int w = static_cast<int>(b);
    const auto in_band = std::count(band.begin(), band.end(), w);
    for (std::size_t h = 0; h < c.tu_bands(); ++h) {
      std::int64_t in_group = 0;
      for (std::size_t i = 0; i < rows.size(); ++i) in_group += band[i] == w && tu_band[i] == static_cast<int>(h);
      std::function<bool(std::size_t)> in = [](std::size_t) { return true; };
      if (in_group >= least) {
        in = [&band, &tu_band, w, h](std::size_t i) { return band[i] == w && tu_band[i] == static_cast<int>(h); };
      } else if (in_band >= least) {
        in = [&band, w](std::size_t i) { return band[i] == w; };
      }
      c.velocity.push_back(offsets(in, 0));
      c.turbulence_intensity.push_back(offsets(in, interval_count));
    }
  }
  set_envelopes(c, model, band, tu_band, shifts);
  return c;
}

namespace {

// The offsets or envelope of a row's group (Calibration::offsets).
template <std::size_t N>
std::array<double, N> group_value(const Calibration& c, const std::vector<std::array<double, N>>& groups,
                                  std::int64_t windows, double tu_median) {
  const auto h = static_cast<std::size_t>(c.tu_band(tu_median));
  const int w = c.band(windows);
  if (w >= 0) return groups[static_cast<std::size_t>(w) * c.tu_bands() + h];
  std::array<double, N> o;
  o.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t b = 0; b <= c.window_edges.size(); ++b)
    for (std::size_t k = 0; k < N; ++k) o[k] = std::max(o[k], groups[b * c.tu_bands() + h][k]);
  return o;
}

}  // namespace

int Calibration::band(std::int64_t windows) const {
  if (windows < 0) return -1;
  int b = 0;
  while (b < static_cast<int>(window_edges.size()) && windows >= window_edges[static_cast<std::size_t>(b)]) ++b;
  return b;
}

int Calibration::tu_band(double tu_median) const {
  int h = 0;
  while (h < static_cast<int>(tu_edges.size()) && tu_median >= tu_edges[static_cast<std::size_t>(h)]) ++h;
  return h;
}

IntervalOffsets Calibration::offsets(const std::vector<IntervalOffsets>& groups, std::int64_t windows,
                                     double tu_median) const {
  return group_value(*this, groups, windows, tu_median);
}

std::optional<std::array<double, 2>> Calibration::envelope(const std::vector<std::array<double, 2>>& groups,
                                                           std::int64_t windows, double tu_median) const {
  if (groups.empty()) return std::nullopt;
  if (groups.size() == 1) return groups.front();
  return group_value(*this, groups, windows, tu_median);
}

std::string Calibration::group_text(std::int64_t windows, double tu_median) const {
  std::string out;
  const int w = band(windows);
  if (window_edges.empty()) {
    out = "all windows";
  } else if (w < 0) {
    out = "windows unknown: the widest band";
  } else if (w == 0) {
    out = fmt::format("windows up to {}", window_edges.front() - 1);
  } else if (w == static_cast<int>(window_edges.size())) {
    out = fmt::format("windows {}+", window_edges.back());
  } else {
    out = fmt::format("windows {}-{}", window_edges[static_cast<std::size_t>(w) - 1],
                      window_edges[static_cast<std::size_t>(w)] - 1);
  }
  if (tu_edges.empty()) return out;
  const auto h = static_cast<std::size_t>(tu_band(tu_median));
  if (h == 0) return fmt::format("{}, model Tu below {:g}", out, tu_edges.front());
  if (h == tu_edges.size()) return fmt::format("{}, model Tu {:g}+", out, tu_edges.back());
  return fmt::format("{}, model Tu {:g}-{:g}", out, tu_edges[h - 1], tu_edges[h]);
}

std::optional<std::array<double, 2>> envelope_of(std::vector<double> shifts, double coverage) {
  const auto n = static_cast<double>(shifts.size());
  // (The rank of an exact product must not round up: 400 x 0.9975 is 399.)
  const auto k = static_cast<std::size_t>(std::ceil((n + 1.0) * (1.0 + coverage) / 2.0 - 1e-9));
  if (shifts.empty() || k > shifts.size()) return std::nullopt;
  std::sort(shifts.begin(), shifts.end());
  // The rule bounds how far from the measurement a median may move: a
  // median nearer to it than the truths lay is not farther, so 0 is inside.
  return std::array<double, 2>{std::max(0.0, -shifts[shifts.size() - k]), std::max(0.0, shifts[k - 1])};
}

void Calibration::apply(const IntervalOffsets& offsets, std::vector<double>& t) {
  for (std::size_t k = 0; k < interval_count; ++k) {
    t[lower_level(k)] -= offsets[k];
    t[upper_level(k)] += offsets[k];
  }
  // A narrowed interval may not cross a narrower one or the median.
  for (std::size_t k = median_level; k-- > 0;) t[k] = std::min(t[k], t[k + 1]);
  for (std::size_t k = median_level + 1; k < t.size(); ++k) t[k] = std::max(t[k], t[k - 1]);
}

}  // namespace correction
