// Campaign loading: the sweep CSVs read into training runs, the durations
// held at the cap, the split into held-out, calibration and training runs,
// unweighted twins and peers' rows.

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

std::string_view to_string(TruthKind truth) { return truth == TruthKind::realised ? "realised" : "imposed"; }

std::optional<TruthKind> truth_kind_of(std::string_view text) {
  if (text == "realised") return TruthKind::realised;
  if (text == "imposed") return TruthKind::imposed;
  return std::nullopt;
}

TrainingSet load_training_set(const std::vector<std::filesystem::path>& csvs, std::int64_t min_windows,
                              TruthKind truth) {
  TrainingSet set;
  std::set<std::pair<std::string, std::int64_t>> seen;
  bool processing_seen = false;
  for (const auto& path : csvs) {
    std::ifstream in(path);
    if (!in) throw awcc::InputError(fmt::format("{}: cannot open the sweep CSV; check the path", path.string()));
    std::string line;
    if (!std::getline(in, line)) throw awcc::InputError(fmt::format("{}: empty file; give a CSV written by pdp sweep", path.string()));
    const auto header = awcc::csv_header(line);
    const auto& col = header.index;
    using C = SweepColumn;
    using Scene = SweepSceneColumns;
    const std::string_view needed[] = {sweep_key_columns[0].name, sweep_key_columns[1].name, Scene::dx, Scene::dy,
                                       column_name(C::np), column_name(C::truth_velocity),
                                       column_name(C::truth_turbulence_intensity), column_name(C::awcc_velocity),
                                       column_name(C::awcc_turbulence_intensity), column_name(C::awcc_void_fraction),
                                       column_name(C::awcc_count_rate), column_name(C::awcc_windows_accepted),
                                       column_name(C::reason),
                                       truth == TruthKind::imposed ? Scene::velocity : column_name(C::truth_velocity),
                                       truth == TruthKind::imposed ? Scene::tu : column_name(C::truth_velocity)};
    for (const auto name : needed) {
      if (!col.count(name)) {
        throw awcc::InputError(fmt::format("{}: no column '{}'; give a CSV written by pdp sweep", path.string(), name));
      }
    }
    // The processing of the runs: every row must agree (the model learns one).
    // Sweeps written before these columns existed have none of them.
    const C processing_columns[] = {C::awcc_filter_a, C::awcc_roc, C::awcc_weighting, C::awcc_signal, C::awcc_subsample};
    const bool has_processing = std::all_of(std::begin(processing_columns), std::end(processing_columns),
                                            [&](C c) { return col.count(column_name(c)) > 0; });
    if (!has_processing) set.processing_assumed = true;
    // The geometry processed; older CSVs have only the scene's dx and dy
    // (the same unless the scene gave explicit tips).
    const std::string_view dx_column = col.count(column_name(C::probe_dx)) ? column_name(C::probe_dx) : Scene::dx;
    const std::string_view dy_column = col.count(column_name(C::probe_dy)) ? column_name(C::probe_dy) : Scene::dy;
    const std::string_view study_column = sweep_key_columns[0].name, run_column = sweep_key_columns[1].name;
    const bool has_version = col.count(column_name(C::generator_version)) > 0;
    std::set<std::string> studies;
    std::int64_t number = 1;
    while (std::getline(in, line)) {
      ++number;
      if (line.empty()) continue;
      const auto cells = split_cells(line);
      if (cells.size() != header.names.size()) {
        throw awcc::InputError(fmt::format("{}:{}: {} cells where the header has {}; a sweep CSV cut short? pdp sweep "
                                           "resumes and repairs it",
                                           path.string(), number, cells.size(), header.names.size()));
      }
      auto cell = [&](std::string_view name) -> const std::string& { return cells[col.find(name)->second]; };
      auto number_of = [&](std::string_view name) {
        const auto v = cell_number(cell(name));
        if (!v) {
          throw awcc::InputError(fmt::format("{}:{}: column {} = '{}' is not a number; give the CSV pdp sweep wrote",
                                             path.string(), number, name, cell(name)));
        }
        return *v;
      };
      ++set.total;
      studies.insert(cell(study_column));
      // Rows written before the column existed are generator version 1.
      set.generator_versions.insert(has_version ? static_cast<int>(number_of(column_name(C::generator_version))) : 1);
      const auto run = static_cast<std::int64_t>(number_of(run_column));
      if (!seen.insert({cell(study_column), run}).second) {
        throw awcc::InputError(fmt::format("{}:{}: run {} of study {} was already read; give each sweep CSV once",
                                           path.string(), number, run, cell(study_column)));
      }
      // A failed run has no result at all (no truth); a run whose AWCC gave
      // no value has its truth but no AWCC velocity.
      if (cell(column_name(C::truth_velocity)).empty()) {
        ++set.excluded_error;
        continue;
      }
      if (has_processing) {
        // An enum cell that names no value is refused: a default would train
        // a model on a processing the runs did not have.
        auto named = [&](C column, auto parse, std::string_view values) {
          const auto v = parse(cell(column_name(column)));
          if (!v) {
            throw awcc::InputError(fmt::format("{}:{}: column {} = '{}' is not one of {}; give the CSV pdp sweep wrote",
                                               path.string(), number, column_name(column), cell(column_name(column)),
                                               values));
          }
          return *v;
        };
        Processing p;
        p.filter_a = number_of(column_name(C::awcc_filter_a));
        p.roc = named(C::awcc_roc, roc_of, "on, off");
        p.weighting = named(C::awcc_weighting, weighting_of, "duration, none");
        p.signal = named(C::awcc_signal, signal_of, "binary, raw");
        p.subsample = named(C::awcc_subsample, subsample_of, "none, parabolic, gaussian, triangle, centroid");
        if (!processing_seen) set.processing = p;
        processing_seen = true;
        if (const auto why = processing_mismatch(set.processing, p); !why.empty()) {
          throw awcc::InputError(fmt::format("{}:{}: this run was processed differently from the first ({}); a model "
                                             "learns one processing: train on sweeps run with the same method options",
                                             path.string(), number, why));
        }
      }
      TrainingRow r;
      r.run = run;
      try {
        std::size_t used = 0;
        r.study = std::stoull(cell(study_column), &used);
        if (used != cell(study_column).size()) throw std::invalid_argument("trailing text");
      } catch (const std::exception&) {
        throw awcc::InputError(fmt::format("{}:{}: study = '{}' is not a sweep study id; give the CSV pdp sweep wrote",
                                           path.string(), number, cell(study_column)));
      }
      Measurement m;
      if (!cell(column_name(C::awcc_velocity)).empty()) m.velocity = number_of(column_name(C::awcc_velocity));
      if (!cell(column_name(C::awcc_turbulence_intensity)).empty())
        m.turbulence_intensity = number_of(column_name(C::awcc_turbulence_intensity));
      auto optional_number = [&](std::string_view name) -> std::optional<double> {
        return col.count(name) && !cell(name).empty() ? std::optional(number_of(name)) : std::nullopt;
      };
      // The phase statistics and the record are there for every run that did not fail.
      m.void_fraction = optional_number(column_name(C::awcc_void_fraction)).value_or(0.0);
      m.bubble_count_rate = optional_number(column_name(C::awcc_count_rate)).value_or(0.0);
      m.dx = number_of(dx_column);
      m.dy = number_of(dy_column);
      m.np = static_cast<int>(number_of(column_name(C::np)));
      m.windows_accepted =
          static_cast<std::int64_t>(optional_number(column_name(C::awcc_windows_accepted)).value_or(-1.0));
      m.windows_total = static_cast<std::int64_t>(optional_number(column_name(C::awcc_windows_total)).value_or(-1.0));
      m.fs = optional_number(Scene::fs).value_or(0.0);
      m.duration = optional_number(Scene::duration).value_or(0.0);
      m.fscc_velocity = optional_number(column_name(C::fscc_velocity));
      m.r12_max = optional_number(column_name(C::fscc_r12_max));
      // Empty where Chanson's Tu is undefined: 0 (correction/features.hpp);
      // a CSV without the column does not state it.
      if (const auto chanson = column_name(C::fscc_turbulence_intensity_chanson); col.count(chanson)) {
        m.tu_chanson = optional_number(chanson).value_or(0.0);
      }
      m.time_scale_ratio = optional_number(column_name(C::awcc_time_scale_ratio));
      // Every row of a set shares one processing (checked above); runs
      // without the columns were processed with the defaults.
      m.weighting = has_processing ? set.processing.weighting : awcc::Weighting::duration;
      const auto features = make_features(m);
      if (truth == TruthKind::realised) {
        r.true_velocity = number_of(column_name(C::truth_velocity));
        r.true_turbulence_intensity = number_of(column_name(C::truth_turbulence_intensity));
      } else {
        r.true_velocity = number_of(Scene::velocity);
        r.true_turbulence_intensity = number_of(Scene::tu);
      }
      if (fscc_unusable(features.features).empty() && features.features.fs > 0.0 && features.features.duration > 0.0) {
        TrainingRow f = r;
        f.features = features.features;
        f.awcc_served = features.ok() && features.features.windows_accepted >= min_windows;
        set.fscc_rows.push_back(f);
      }
      if (!features.ok()) {  // no (positive) AWCC velocity, or no bubbles: not corrected either
        ++set.excluded_undefined;
        continue;
      }
      if (features.features.windows_accepted < min_windows) {
        ++set.excluded_windows;
        continue;
      }
      r.features = features.features;
      // The same windows' unweighted moments, where the sweep wrote them.
      const auto u_unweighted = optional_number(column_name(C::awcc_velocity_unweighted));
      const auto tu_unweighted = optional_number(column_name(C::awcc_turbulence_intensity_unweighted));
      if (u_unweighted && tu_unweighted) {
        Measurement twin = m;
        twin.velocity = u_unweighted;
        twin.turbulence_intensity = tu_unweighted;
        twin.weighting = awcc::Weighting::none;
        if (const auto t = make_features(twin); t.ok()) r.unweighted = t.features;
      }
      set.rows.push_back(r);
    }
    for (const auto& s : studies) set.sources.push_back(fmt::format("{} (study {})", path.filename().string(), s));
  }
  if (set.rows.empty()) {
    throw awcc::InputError(fmt::format("no usable runs in the sweep CSVs ({} read: {} failed, {} without an AWCC "
                                       "velocity, {} with fewer than {} accepted windows): give sweeps with usable "
                                       "runs, or lower min-windows",
                                       set.total, set.excluded_error, set.excluded_undefined, set.excluded_windows,
                                       min_windows),
                           "min-windows");
  }
  return set;
}

double duration_cap(const std::vector<TrainingRow>& rows) {
  std::vector<double> d;
  d.reserve(rows.size());
  for (const auto& r : rows)
    if (r.features.duration > 0.0) d.push_back(r.features.duration);
  if (d.empty()) return 0.0;
  std::sort(d.begin(), d.end());
  const auto above = static_cast<std::size_t>(std::floor(duration_saturation_share * static_cast<double>(d.size())));
  return d[d.size() - 1 - above];
}

namespace detail {

// The rows as the forests see them: durations above the cap at the cap.
std::vector<TrainingRow> with_saturated_durations(std::vector<TrainingRow> rows) {
  const double cap = duration_cap(rows);
  for (auto& r : rows) {
    r.features.duration = std::min(r.features.duration, cap);
    if (r.unweighted) r.unweighted->duration = std::min(r.unweighted->duration, cap);
  }
  return rows;
}

Split split_runs(std::vector<TrainingRow> rows, const TrainOptions& o) {
  auto key = [&](const TrainingRow& r) { return mix64(o.seed ^ mix64(static_cast<std::uint64_t>(r.run) ^ mix64(r.study))); };
  std::sort(rows.begin(), rows.end(), [&](const TrainingRow& a, const TrainingRow& b) {
    const auto ha = key(a), hb = key(b);
    if (ha != hb) return ha < hb;
    return a.study != b.study ? a.study < b.study : a.run < b.run;
  });
  const auto held = static_cast<std::size_t>(std::llround(o.held_out * static_cast<double>(rows.size())));
  const auto calibrating = static_cast<std::size_t>(std::llround(o.calibration * static_cast<double>(rows.size() - held)));
  const auto at = [&](std::size_t i) { return rows.begin() + static_cast<std::ptrdiff_t>(i); };
  return {{rows.begin(), at(held)}, {at(held), at(held + calibrating)}, {at(held + calibrating), rows.end()}};
}

}  // namespace detail

namespace detail {

// The rows and, after each that has one, its unweighted twin (the same run's
// windows with unweighted moments, feature awcc_unweighted 1).
std::vector<TrainingRow> with_unweighted_twins(const std::vector<TrainingRow>& rows) {
  std::vector<TrainingRow> out;
  out.reserve(2 * rows.size());
  for (const auto& r : rows) {
    out.push_back(r);
    if (!r.unweighted) continue;
    TrainingRow twin = r;
    twin.features = *r.unweighted;
    twin.unweighted.reset();
    out.push_back(std::move(twin));
  }
  return out;
}

}  // namespace detail

std::vector<TrainingRow> as_peer_rows(std::vector<TrainingRow> rows) {
  for (auto& r : rows) {
    for (auto* f : {&r.features, r.unweighted ? &*r.unweighted : nullptr}) {
      if (!f) continue;
      f->fs = 0.0;
      f->duration = 0.0;
      f->windows_accepted = -1;
      f->windows_total = -1;
      f->time_scale_ratio = 0.0;
    }
  }
  return rows;
}

}  // namespace correction
