#include "awcc/serialise.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <span>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/options.hpp"
#include "awcc/read_back.hpp"
#include "awcc/sha256.hpp"
#include "awcc/version.hpp"

namespace awcc {

namespace {

// Each column with its CSV number format (fmt), which keeps the table's digits as they were.
struct WindowColumnFormat {
  WindowColumn column;
  std::string_view format;
};
constexpr WindowColumnFormat kWindowColumns[] = {
    {{"start_time", "s", [](const AwccWindow& w) { return w.start_time; }, nullptr}, "{:.9g}"},
    {{"duration", "s", [](const AwccWindow& w) { return w.duration; }, nullptr}, "{:.9g}"},
    {{"particles", "-", [](const AwccWindow& w) { return static_cast<double>(w.particles); }, nullptr}, "{:.0f}"},
    {{"lag", "s", [](const AwccWindow& w) { return w.lag; }, nullptr}, "{:.9g}"},
    {{"velocity", "m/s", [](const AwccWindow& w) { return w.velocity; }, nullptr}, "{:.9g}"},
    {{"r12_max", "-", [](const AwccWindow& w) { return w.r12_max; }, nullptr}, "{:.6f}"},
    {{"spr", "-", [](const AwccWindow& w) { return w.spr; }, nullptr}, "{:.6f}"},
    {{"void_fraction", "-", [](const AwccWindow& w) { return w.void_fraction; }, nullptr}, "{:.6f}"},
    {{"count_rate", "1/s", [](const AwccWindow& w) { return w.count_rate; }, nullptr}, "{:.6g}"},
    {{"fate", "", nullptr, [](const AwccWindow& w) { return to_string(w.fate); }}, "{}"},
    {{"measured_velocity", "m/s", [](const AwccWindow& w) { return w.measured_velocity; }, nullptr}, "{:.9g}"},
};

// Each column of the bubble table with its CSV number format.
struct BubbleColumnFormat {
  BubbleColumn column;
  std::string_view format;
};
constexpr BubbleColumnFormat kBubbleColumns[] = {
    {{"leading_front", "s", [](const EventBubble& b) { return b.leading_front; }, nullptr}, "{:.9g}"},
    {{"leading_rear", "s", [](const EventBubble& b) { return b.leading_rear; }, nullptr}, "{:.9g}"},
    {{"trailing_front", "s", [](const EventBubble& b) { return b.trailing_front; }, nullptr}, "{:.9g}"},
    {{"trailing_rear", "s", [](const EventBubble& b) { return b.trailing_rear; }, nullptr}, "{:.9g}"},
    {{"front_lag", "s", [](const EventBubble& b) { return b.front_lag; }, nullptr}, "{:.9g}"},
    {{"rear_lag", "s", [](const EventBubble& b) { return b.rear_lag; }, nullptr}, "{:.9g}"},
    {{"centre_lag", "s", [](const EventBubble& b) { return b.centre_lag; }, nullptr}, "{:.9g}"},
    {{"disparity", "-", [](const EventBubble& b) { return b.disparity; }, nullptr}, "{:.6f}"},
    {{"velocity", "m/s", [](const EventBubble& b) { return b.velocity; }, nullptr}, "{:.9g}"},
    {{"chord_length", "m", [](const EventBubble& b) { return b.chord_length; }, nullptr}, "{:.9g}"},
    {{"weight", "s", [](const EventBubble& b) { return b.weight; }, nullptr}, "{:.9g}"},
    {{"fate", "", nullptr, [](const EventBubble& b) { return to_string(b.fate); }}, "{}"},
};

struct VectorColumnFormat {
  VectorColumn column;
  std::string_view format;
};
constexpr VectorColumnFormat kVectorColumns[] = {
    {{"time", "s", [](const BubbleVector& b) { return b.time; }, nullptr}, "{:.9g}"},
    {{"velocity_x", "m/s", [](const BubbleVector& b) { return b.velocity[0]; }, nullptr}, "{:.9g}"},
    {{"velocity_y", "m/s", [](const BubbleVector& b) { return b.velocity[1]; }, nullptr}, "{:.9g}"},
    {{"velocity_z", "m/s", [](const BubbleVector& b) { return b.velocity[2]; }, nullptr}, "{:.9g}"},
    {{"speed", "m/s", [](const BubbleVector& b) { return std::hypot(b.velocity[0], b.velocity[1], b.velocity[2]); },
      nullptr},
     "{:.9g}"},
    {{"velocity_spread_x", "m/s", [](const BubbleVector& b) { return b.velocity_spread[0]; }, nullptr}, "{:.6g}"},
    {{"velocity_spread_y", "m/s", [](const BubbleVector& b) { return b.velocity_spread[1]; }, nullptr}, "{:.6g}"},
    {{"velocity_spread_z", "m/s", [](const BubbleVector& b) { return b.velocity_spread[2]; }, nullptr}, "{:.6g}"},
    {{"diameter_front", "m", [](const BubbleVector& b) { return b.diameter_front; }, nullptr}, "{:.9g}"},
    {{"diameter_rear", "m", [](const BubbleVector& b) { return b.diameter_rear; }, nullptr}, "{:.9g}"},
    {{"normal_front_x", "-", [](const BubbleVector& b) { return b.normal_front[0]; }, nullptr}, "{:.6f}"},
    {{"normal_front_y", "-", [](const BubbleVector& b) { return b.normal_front[1]; }, nullptr}, "{:.6f}"},
    {{"normal_front_z", "-", [](const BubbleVector& b) { return b.normal_front[2]; }, nullptr}, "{:.6f}"},
    {{"area_share", "s/m", [](const BubbleVector& b) { return b.area_share; }, nullptr}, "{:.9g}"},
    {{"weight", "s", [](const BubbleVector& b) { return b.weight; }, nullptr}, "{:.9g}"},
    {{"combinations", "-", [](const BubbleVector& b) { return static_cast<double>(b.combinations); }, nullptr}, "{:.0f}"},
    {{"combinations_skipped", "-", [](const BubbleVector& b) { return static_cast<double>(b.combinations_skipped); },
      nullptr},
     "{:.0f}"},
    {{"fate", "", nullptr, [](const BubbleVector& b) { return to_string(b.fate); }}, "{}"},
};

// The columns of a table without their formats.
template <class Format, std::size_t N>
auto columns_of(const Format (&formats)[N]) {
  std::vector<decltype(formats[0].column)> out;
  for (const auto& c : formats) out.push_back(c.column);
  return out;
}

// A table's CSV from its formatted columns: a header of their names, one
// line per row, an empty cell for a number that is not finite.
template <class Format, std::size_t N, class Row>
std::string table_csv(const Format (&columns)[N], const std::vector<Row>& rows) {
  std::string out;
  for (const auto& c : columns) out += fmt::format("{}{}", out.empty() ? "" : ",", c.column.name);
  out += '\n';
  for (const auto& row : rows) {
    bool first = true;
    for (const auto& c : columns) {
      if (!first) out += ',';
      first = false;
      if (c.column.text) {
        out += c.column.text(row);
      } else if (const double v = c.column.value(row); std::isfinite(v)) {
        out += fmt::format(fmt::runtime(c.format), v);
      }
    }
    out += '\n';
  }
  return out;
}

// The JSON's count of the windows of a fate: windows_accepted, windows_rejected_<fate>.
std::string window_count_key(WindowFate fate) {
  return fate == WindowFate::accepted ? std::string(process_key::windows_accepted) : fmt::format("windows_rejected_{}", to_string(fate));
}

}  // namespace

namespace {

// Each enum's values: its parser reads, and written_values lists, their
// to_string texts, so that a renamed value is read as it is written.
constexpr PhaseStatus kPhaseStatuses[] = {PhaseStatus::ok, PhaseStatus::no_air, PhaseStatus::all_air,
                                          PhaseStatus::too_few_chords};
constexpr FsccStatus kFsccStatuses[] = {FsccStatus::ok,
                                        FsccStatus::constant_leading,
                                        FsccStatus::constant_trailing,
                                        FsccStatus::no_common_segment,
                                        FsccStatus::no_positive_peak,
                                        FsccStatus::non_positive_lag,
                                        FsccStatus::tips_swapped,
                                        FsccStatus::peak_at_lag_range_end,
                                        FsccStatus::no_tip_separation};
constexpr AwccStatus kAwccStatuses[] = {AwccStatus::ok,           AwccStatus::too_few_particles,
                                        AwccStatus::delay_below_one_sample, AwccStatus::too_few_windows,
                                        AwccStatus::tips_swapped, AwccStatus::no_tip_separation};
constexpr AwccQuality kAwccQualities[] = {AwccQuality::ok, AwccQuality::low, AwccQuality::insufficient};
constexpr MultiTipStatus kMultiTipStatuses[] = {MultiTipStatus::ok, MultiTipStatus::too_few_bubbles};
constexpr WindowFate kWindowFates[] = {WindowFate::accepted, WindowFate::correlation, WindowFate::lag,
                                       WindowFate::roc,      WindowFate::constant,    WindowFate::too_short,
                                       WindowFate::correction};
constexpr SizesStatus kSizesStatuses[] = {SizesStatus::ok,
                                          SizesStatus::not_converged,
                                          SizesStatus::no_velocity,
                                          SizesStatus::intermediate_void_fraction,
                                          SizesStatus::too_few_chords,
                                          SizesStatus::coarse_sampling};
constexpr AreaSource kAreaSources[] = {AreaSource::dual_tip, AreaSource::multi_tip};
constexpr VelocitySource kVelocitySources[] = {VelocitySource::none, VelocitySource::awcc, VelocitySource::fscc};
constexpr auto kFlags = [] {
  std::array<Flag, flag_names.size()> out{};
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = flag_names[i].flag;
  return out;
}();

constexpr bool kSwitches[] = {true, false};

template <class E>
std::string_view text_of(E v) {
  return to_string(v);
}
std::string_view text_of(bool on) { return switch_text(on); }

template <class Values>
std::vector<std::string_view> texts(const Values& values) {
  std::vector<std::string_view> out;
  for (const auto v : values) out.push_back(text_of(v));
  return out;
}

template <class Values, class E = std::remove_cvref_t<decltype(*std::begin(std::declval<const Values&>()))>>
E parse_written(std::string_view text, const Values& values, const WrittenAt& at) {
  for (const E v : values) {
    if (text_of(v) == text) return v;
  }
  std::string known;
  for (const auto t : texts(values)) known += fmt::format("{}{}", known.empty() ? "" : ", ", t);
  throw InputError(fmt::format("{}: {}: {} = '{}' is not a value pdp writes ({}); give a file written by pdp process",
                               at.file, at.row, at.field, text, known));
}

}  // namespace

PhaseStatus parse_phase_status(std::string_view text, const WrittenAt& at) {
  return parse_written(text, kPhaseStatuses, at);
}
FsccStatus parse_fscc_status(std::string_view text, const WrittenAt& at) {
  return parse_written(text, kFsccStatuses, at);
}
AwccStatus parse_awcc_status(std::string_view text, const WrittenAt& at) {
  return parse_written(text, kAwccStatuses, at);
}
AwccQuality parse_awcc_quality(std::string_view text, const WrittenAt& at) {
  return parse_written(text, kAwccQualities, at);
}
Weighting parse_weighting(std::string_view text, const WrittenAt& at) { return parse_written(text, values::weighting, at); }
CorrelationSignal parse_correlation_signal(std::string_view text, const WrittenAt& at) {
  return parse_written(text, values::signal, at);
}
Subsample parse_subsample(std::string_view text, const WrittenAt& at) { return parse_written(text, values::subsample, at); }
WindowFate parse_window_fate(std::string_view text, const WrittenAt& at) {
  return parse_written(text, kWindowFates, at);
}
VelocitySource parse_velocity_source(std::string_view text, const WrittenAt& at) {
  return parse_written(text, kVelocitySources, at);
}
bool parse_switch(std::string_view text, const WrittenAt& at) { return parse_written(text, kSwitches, at); }
Flag parse_flag(std::string_view text, const WrittenAt& at) { return parse_written(text, kFlags, at); }

std::vector<Flag> parse_flags_cell(std::string_view cell, const WrittenAt& at) {
  std::vector<Flag> out;
  for (std::size_t from = 0; from < cell.size();) {
    const auto end = std::min(cell.find("; ", from), cell.size());
    out.push_back(parse_flag(cell.substr(from, end - from), at));
    from = end + 2;
  }
  return out;
}

std::vector<std::string_view> written_values(std::string_view column) {
  namespace c = profile_column;
  if (column == c::fscc_status) return texts(kFsccStatuses);
  if (column == c::awcc_status) return texts(kAwccStatuses);
  if (column == c::awcc_quality || column == c::events_quality || column == c::multi_tip_quality) {
    return texts(kAwccQualities);
  }
  if (column == c::multi_tip_status) return texts(kMultiTipStatuses);
  if (column == c::awcc_weighting) return texts(values::weighting);
  if (column == c::awcc_signal) return texts(values::signal);
  if (column == c::awcc_subsample) return texts(values::subsample);
  if (column == c::chord_velocity_source) return texts(kVelocitySources);
  if (column == c::sizes_status) return texts(kSizesStatuses);
  if (column == c::interfacial_area_source) return texts(kAreaSources);
  if (column == c::awcc_roc || column == c::awcc_probe_corrected) return texts(kSwitches);
  if (column == c::flags) return texts(kFlags);
  return {};
}

std::span<const WindowColumn> awcc_window_columns() {
  static const auto columns = columns_of(kWindowColumns);
  return columns;
}

std::string awcc_windows_csv(const AwccResult& result) { return table_csv(kWindowColumns, result.windows); }

std::span<const BubbleColumn> event_bubble_columns() {
  static const auto columns = columns_of(kBubbleColumns);
  return columns;
}

std::string event_bubbles_csv(const EventResult& result) { return table_csv(kBubbleColumns, result.bubbles); }

std::span<const VectorColumn> multi_tip_bubble_columns() {
  static const auto columns = columns_of(kVectorColumns);
  return columns;
}

std::string multi_tip_bubbles_csv(const MultiTipResult& result) { return table_csv(kVectorColumns, result.bubbles); }

namespace {

using nlohmann::json;

json optional(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

json ci(const Interval95& i) { return json::array({i.lower, i.upper}); }

json summary(const Summary& s) {
  json pct = json::object();
  for (std::size_t i = 0; i < s.percentiles.size(); ++i) pct[fmt::format("{:g}", Summary::levels[i])] = s.percentiles[i];
  return json{{"count", s.count}, {"mean", s.mean},       {"median", s.median},         {"std", s.std},
              {"min", s.min},     {"max", s.max},         {"percentiles", pct},         {"mean_ci95", ci(s.mean_ci95)},
              {"median_ci95", ci(s.median_ci95)}};
}

json histogram(const Histogram& h) { return json{{"bin_width", h.bin_width}, {"counts", h.counts}}; }

}  // namespace

namespace {

template <class T>
void add_options(json& out, std::span<const OptionField<T>> fields, const T& target) {
  for (const auto& f : fields) out[std::string(f.name)] = f.format(target);
}

}  // namespace

json options_json(const ProcessOptions& o) {
  json out = json::object();
  add_options(out, process_option_fields(), o);
  add_options(out, reader_option_fields(), o.reader);
  add_options(out, binarisation_option_fields(), o.binarisation);
  add_options(out, fscc_option_fields(), o.fscc_options);
  add_options(out, awcc_option_fields(), o.awcc_options);
  add_options(out, structure_option_fields(), o.structure);
  add_options(out, event_option_fields(), o.event_options);
  add_options(out, multi_tip_option_fields(), o.multi_tip_options);
  return out;
}

json provenance_json(const ProcessOptions& options, const std::vector<ProvenanceInput>& inputs,
                     const std::string& command_line) {
  json files = json::array();
  for (const auto& input : inputs) {
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(input.file, ec);
    const std::string digest = input.sha256.empty() ? sha256_of_file(input.file) : input.sha256;
    files.push_back(json{{"file", input.file}, {"bytes", ec ? json(nullptr) : json(bytes)}, {"sha256", digest}});
  }
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char when[32];
  std::strftime(when, sizeof when, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return json{{"pdp_version", version},
              {"command_line", command_line},
              {"options", options_json(options)},
              {"inputs", files},
              {"utc_time", when}};
}

json to_json(const AwccOptions& o) {
  return json{{process_key::np, o.np},
              {process_key::filter_a, o.filter_a},
              {process_key::roc, o.roc},
              {process_key::weighting, to_string(o.weighting)},
              {process_key::signal, to_string(o.signal)},
              {process_key::subsample, to_string(o.subsample)},
              {"prominence_fraction", o.prominence_fraction},
              {"velocity_min", optional(o.velocity_min)},
              {"velocity_max", optional(o.velocity_max)}};
}

namespace {

json optional_array(const std::optional<std::array<double, 20>>& a) { return a ? json(*a) : json(nullptr); }

json to_json(const ChordPdf& p) {
  std::vector<double> lower;
  for (std::size_t k = 0; k < p.air_counts.size(); ++k) lower.push_back(p.lower_edge(k));
  return json{{"basis", to_string(p.basis)},   {"bin_width", p.bin_width},       {"max", p.max},
              {"air_chords", p.air_chords},     {"water_chords", p.water_chords}, {"lower_edges", lower},
              {"air_counts", p.air_counts},     {"air_fraction", p.air_fraction}, {"water_counts", p.water_counts},
              {"water_fraction", p.water_fraction}};
}

json to_json(const VoltagePdf& p) {
  return json{{"lower", p.lower}, {"upper", p.upper}, {"fraction", p.fraction}, {"samples", p.samples}};
}

json to_json(const ClusterAnalysis& c) {
  json criteria = json::object();
  for (const auto& s : c.criteria) {
    criteria[std::string(to_string(s.criterion))] = json{
        {"criterion_value", optional(s.criterion_value)},
        {"n_particles", s.particles},
        {"n_in_clusters", s.in_clusters},
        {"pct_in_clusters", s.percent_in_clusters},
        {"n_clusters", s.clusters},
        {"clusters_per_s", s.clusters_per_second},
        {"mean_particles_per_cluster", optional(s.mean_particles_per_cluster)},
        {"mean_chord_in_cluster", optional(s.mean_chord_in_cluster)},
        {"ratio_cluster_chord_to_mean_chord", optional(s.ratio_cluster_chord_to_mean_chord)},
        {"ratio_lead_to_cluster_mean_chord", optional(s.ratio_lead_to_cluster_mean_chord)},
        {"size_counts", s.size_counts},
        {"size_pdf", optional_array(s.size_pdf)},
    };
  }
  return json{{"status", to_string(c.status)},
              {"reason", c.message.empty() ? json(nullptr) : json(c.message)},
              {"regime", to_string(c.regime)},
              {"basis", to_string(c.basis)},
              {"criteria", criteria}};
}

json to_json(const ArrivalAnalysis& a) {
  json classes = json::array();
  for (const auto& c : a.classes) {
    classes.push_back(json{{"lower", optional(c.lower)},
                           {"upper", optional(c.upper)},
                           {"particles", c.particles},
                           {"intervals", c.intervals},
                           {"counts", c.counts},
                           {"pdf", c.pdf.empty() ? json(nullptr) : json(c.pdf)},
                           {"reference", c.reference.empty() ? json(nullptr) : json(c.reference)},
                           {"excess_first_bin", optional(c.excess_first_bin)},
                           {"excess_first_bin_se", optional(c.excess_first_bin_se)}});
  }
  return json{{"status", to_string(a.status)},
              {"reason", a.message.empty() ? json(nullptr) : json(a.message)},
              {"regime", to_string(a.regime)},
              {"basis", to_string(a.basis)},
              {"bin_width", a.bin_width},
              {"classes", classes}};
}

}  // namespace

json felder_counts(const StructureResult& r) {
  if (!r.felder_counts) return nullptr;
  json tips = json::array();
  for (const auto& c : *r.felder_counts) {
    tips.push_back(json{{"void_fraction", c.void_fraction}, {"bubble_count_rate", c.bubble_count_rate}, {"bubbles", c.bubbles}});
  }
  return tips;
}

json to_json(const StructureResult& r) {
  auto volts = [](const std::optional<VoltagePdf>& p) { return p ? to_json(*p) : json(nullptr); };
  return json{{"conventions", r.felder_defects ? "felder" : "default"},
              {"bubbles_used", r.bubbles_used},
              {"chord_velocity", optional(r.velocity)},
              {"chord_velocity_source", r.velocity_source},
              {"voltage_pdf", json{{"leading", volts(r.voltage_leading)}, {"trailing", volts(r.voltage_trailing)}}},
              {"chord_time_pdf", to_json(r.chord_time)},
              {"chord_length_pdf", r.chord_length ? to_json(*r.chord_length) : json(nullptr)},
              {"clusters", json{{"time", to_json(r.clusters_time)}, {"length", to_json(r.clusters_length)}}},
              {"arrivals", json{{"time", to_json(r.arrivals_time)}, {"length", to_json(r.arrivals_length)}}},
              {"felder_counts", felder_counts(r)}};
}

json to_json(const Threshold& t) {
  json out{{"threshold", t.threshold},
           {"threshold_rule", std::string(to_string(t.rule))},
           {"threshold_lower", t.lower},
           {"threshold_upper", t.upper},
           {"air_level", t.air_level},
           {"water_level", t.water_level},
           {"binary_input", t.binary_input}};
  if (!t.note.empty()) out["threshold_note"] = t.note;
  return out;
}

namespace {

std::vector<std::string> warning_texts(const ProcessResult& r) {
  std::vector<std::string> out;
  for (const auto& w : r.warnings) out.push_back(w.text);
  return out;
}

std::vector<std::string> flag_codes(const ProcessResult& r) {
  std::vector<std::string> out;
  for (const auto& w : r.warnings) out.emplace_back(to_string(w.flag));
  return out;
}

// A list as the profile CSV writes it in one cell.
std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) out += (out.empty() ? "" : "; ") + s;
  return out;
}

// A tip's signal check (awcc/signal_check.hpp): what it saw and whether a
// failure was processed anyway.
json to_json(const SignalCheck& s) {
  return json{{process_key::status, to_string(s.status)},
              {"message", s.message.empty() ? json(nullptr) : json(s.message)},
              {"overridden", s.overridden},
              {"low_level", s.low_level},
              {"high_level", s.high_level},
              {"flatness", s.flatness},
              {"minor_share", s.minor_share},
              {"rail_share", s.rail_share},
              {"air_share", s.air_share}};
}

}  // namespace

namespace {

json tip_json(const TipResult& t) {
  const auto& p = t.phase;
  json tip{
      {"channel", t.channel},
      {"name", t.name.empty() ? json(nullptr) : json(t.name)},
      {process_key::status, to_string(p.status)},
      {"status_message", p.message.empty() ? json(nullptr) : json(p.message)},
      {process_key::void_fraction, p.void_fraction},
      {process_key::void_fraction_ci95, ci(p.void_fraction_ci95)},
      {process_key::bubble_count_rate, p.bubble_count_rate},
      {process_key::bubble_count_rate_ci95, ci(p.bubble_count_rate_ci95)},
      {"chord_time_mean", p.air_chord_time.mean},
      {"chord_time_median", p.air_chord_time.median},
      {"air_chord_time", summary(p.air_chord_time)},
      {"water_chord_time", summary(p.water_chord_time)},
      {"interarrival_time", summary(p.interarrival_time)},
      {"air_chord_time_histogram", histogram(p.air_chord_histogram)},
      {"water_chord_time_histogram", histogram(p.water_chord_histogram)},
      {"chord_length", p.air_chord_length ? summary(*p.air_chord_length) : json(nullptr)},
      {"sauter_diameter", optional(p.sauter_diameter)},
  };
  tip.update(to_json(t.threshold));
  tip[process_key::signal] = to_json(t.signal);
  return tip;
}

json fscc_json(const FsccResult& f) {
  json out{
      {process_key::status, to_string(f.status)},
      {process_key::reason, f.ok() ? json(nullptr) : json(f.message)},
      {process_key::velocity, f.ok() ? json(f.velocity) : json(nullptr)},
      {process_key::velocity_ci95, f.ok() && f.velocity_ci95 ? ci(*f.velocity_ci95) : json(nullptr)},
      {"interval_segments", f.interval_segments},
      {"lag", f.lag},
      {"lag_samples", f.lag_samples},
      {process_key::r12_max, f.r12_max},
      {"t05", optional(f.t05)},
      {"tau05", optional(f.tau05)},
      {"txx", optional(f.txx)},
      {"txy", optional(f.txy)},
      {process_key::turbulence_intensity_chanson, optional(f.turbulence_intensity_chanson)},
      {"note", f.note.empty() ? json(nullptr) : json(f.note)},
      {"warnings", f.warnings},
      {process_key::signal, to_string(f.signal)},
      {"segments_used", f.segments_used},
      {"t_r11_zero", optional(f.t_r11_zero)},
      {"t_r11_min", optional(f.t_r11_min)},
      {"r11_min", optional(f.r11_min)},
      {"t_half", optional(f.t_half)},
      {"t_r12_zero", optional(f.t_r12_zero)},
      {"t_r12_min", optional(f.t_r12_min)},
      {"r12_min", optional(f.r12_min)},
  };
  json notes = json::object();
  for (const auto& [name, why] : f.scale_notes) notes[name] = why;
  out["scale_notes"] = notes;
  return out;
}

json awcc_json(const AwccResult& a) {
  auto value = [&](double v) { return a.ok() ? json(v) : json(nullptr); };
  auto interval = [&](const Interval95& i) { return a.ok() ? ci(i) : json(nullptr); };
  // The spread and Tu where they are measured (AwccResult::turbulence_measured).
  auto spread = [&](double v) { return a.turbulence_measured ? value(v) : json(nullptr); };
  auto spread_interval = [&](const Interval95& i) { return a.turbulence_measured ? interval(i) : json(nullptr); };
  json out{
      {process_key::status, to_string(a.status)},
      {process_key::reason, a.ok() ? json(nullptr) : json(a.message)},
      {process_key::np, a.np},
      {process_key::options, to_json(a.options)},
      {process_key::velocity, value(a.velocity)},
      {process_key::velocity_ci95, interval(a.velocity_ci95)},
      {"velocity_rms", spread(a.velocity_rms)},
      {"velocity_rms_ci95", spread_interval(a.velocity_rms_ci95)},
      {process_key::turbulence_intensity, spread(a.turbulence_intensity)},
      {"turbulence_intensity_ci95", spread_interval(a.turbulence_intensity_ci95)},
      {process_key::turbulence_measured, a.ok() ? json(a.turbulence_measured) : json(nullptr)},
      {process_key::windows_at_least_lag, a.windows_at_least_lag},
      {process_key::windows_at_greatest_lag, a.windows_at_greatest_lag},
      {process_key::windows_total, a.windows_total},
      {"windows_lag_zero", a.lag_zero_windows},
      {"roc_iterations", a.roc_iterations},
      {"windows_negative_lag", a.negative_lag_windows},
      {"quality", to_string(a.quality)},
      {process_key::quality_reason, a.quality_reason.empty() ? json(nullptr) : json(a.quality_reason)},
      {process_key::probe_corrected, a.probe_corrected},
      {"velocity_measured", a.probe_corrected ? value(a.velocity_measured) : json(nullptr)},
      {"velocity_rms_measured", a.probe_corrected ? value(a.velocity_rms_measured) : json(nullptr)},
      {"turbulence_intensity_measured", a.probe_corrected ? value(a.turbulence_intensity_measured) : json(nullptr)},
      {"windows_not_bubbly", a.windows_not_bubbly},
      {process_key::time_scale_ratio, a.time_scale_ratio ? json(*a.time_scale_ratio) : json(nullptr)},
      {"weighting_gap", a.ok() && a.weighting_gap ? json{{"value", a.weighting_gap->value},
                                                         {"ci95", ci(a.weighting_gap->ci95)},
                                                         {"allowance", a.weighting_gap->allowance},
                                                         {"along_flow", a.weighting_gap->along_flow}}
                                                   : json(nullptr)},
      {"yield", a.windows_total > 0 ? json(static_cast<double>(a.windows_accepted) /
                                            static_cast<double>(a.windows_total))
                                      : json(nullptr)},
  };
  // From the counts by fate (nlohmann::json sorts an object's keys: the
  // file reads as when they were listed by hand).
  for (std::size_t i = 0; i < window_fate_count; ++i) {
    const auto fate = static_cast<WindowFate>(i);
    out[window_count_key(fate)] = a.count(fate);
  }
  return out;
}

json vec(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }

json events_json(const EventResult& e) {
  auto value = [&](double v) { return e.ok() ? json(v) : json(nullptr); };
  auto interval = [&](const Interval95& i) { return e.ok() ? ci(i) : json(nullptr); };
  auto spread = [&](double v) { return e.turbulence_measured ? value(v) : json(nullptr); };
  auto spread_interval = [&](const Interval95& i) { return e.turbulence_measured ? interval(i) : json(nullptr); };
  json out{
      {process_key::status, to_string(e.status)},
      {process_key::reason, e.ok() ? json(nullptr) : json(e.message)},
      {"quality", to_string(e.quality)},
      {"quality_reason", e.quality_reason.empty() ? json(nullptr) : json(e.quality_reason)},
      {"pairing", to_string(e.options.pairing)},
      {"interface_times", to_string(e.options.interface_times)},
      {"interface_times_note", e.interface_times_note.empty() ? json(nullptr) : json(e.interface_times_note)},
      {"first_velocity", optional(e.first_velocity)},
      {process_key::velocity, value(e.velocity)},
      {"velocity_ci95", interval(e.velocity_ci95)},
      {"velocity_rms", spread(e.velocity_rms)},
      {"velocity_rms_ci95", spread_interval(e.velocity_rms_ci95)},
      {process_key::turbulence_intensity, spread(e.turbulence_intensity)},
      {"turbulence_intensity_ci95", spread_interval(e.turbulence_intensity_ci95)},
      {process_key::turbulence_measured, e.ok() ? json(e.turbulence_measured) : json(nullptr)},
      {"bubbles_total", e.bubbles_total},
      {"bubbles_complete", e.bubbles_complete},
      {"bubbles_paired", e.bubbles_paired},
      {"yield", e.bubbles_complete > 0 ? json(static_cast<double>(e.bubbles_paired) /
                                              static_cast<double>(e.bubbles_complete))
                                        : json(nullptr)},
      {"roc_iterations", e.roc_iterations},
      {"chord_length", e.ok() ? summary(e.chord_length) : json(nullptr)},
      {"sauter_diameter", value(e.sauter_diameter)},
  };
  json fates = json::object();
  for (std::size_t i = 0; i < bubble_fate_count; ++i) fates[std::string(bubble_fate_names[i])] = e.bubbles_by_fate[i];
  out["bubbles_by_fate"] = fates;
  return out;
}

json sizes_json(const SizesResult& r) {
  namespace k = process_key;
  const SizeDistribution& d = r.distribution;
  const bool dist = r.has_distribution();
  auto value = [&](double v) { return dist ? json(v) : json(nullptr); };
  json by = json::object();
  for (std::size_t i = 0; i < chord_velocity_names.size(); ++i) {
    by[std::string(chord_velocity_names[i])] = r.chords_by_velocity[i];
  }
  json bins = nullptr;
  if (dist) {
    bins = json{{k::bin_edges, d.edges}, {k::bin_diameters, d.diameters}, {k::bin_density, d.density},
                {k::bin_cumulative, d.cumulative}};
  }
  return json{{k::status, to_string(r.status)},
              {k::reason, r.message.empty() ? json(nullptr) : json(r.message)},
              {"velocity_note", r.velocity_note.empty() ? json(nullptr) : json(r.velocity_note)},
              {k::dispersed_phase, r.phase ? json(to_string(*r.phase)) : json(nullptr)},
              {"chords_given", r.chords_given},
              {k::chords_used, d.chords_used},
              {"chords_by_velocity", by},
              {"record_velocity_source", r.record_velocity_source},
              {"mean_chord", d.chords_used > 0 ? json(d.mean_chord) : json(nullptr)},
              {"median_samples", dist || r.status == SizesStatus::coarse_sampling ? json(r.median_samples)
                                                                                  : json(nullptr)},
              {k::median, value(d.median)},
              {k::d10, value(d.d10)},
              {k::d20, value(d.d20)},
              {k::d30, value(d.d30)},
              {k::d32, value(d.d32)},
              {k::d32_chords, d.chords_used > 0 ? json(d.sauter_from_chords) : json(nullptr)},
              {k::d32_flux, optional(r.sauter_flux)},
              {"iterations", dist ? json(d.iterations) : json(nullptr)},
              {k::bins, bins}};
}

json interfacial_area_json(const InterfacialArea& a) {
  auto interval = [](const std::optional<Interval95>& i) { return i ? ci(*i) : json(nullptr); };
  return json{{"value", optional(a.value())},
              {"ci95", interval(a.ci95())},
              {"source", a.source ? json(to_string(*a.source)) : json(nullptr)},
              {"dual_tip", optional(a.dual_tip)},
              {"dual_tip_ci95", interval(a.dual_tip_ci95)},
              {"multi_tip", optional(a.multi_tip)},
              {"multi_tip_ci95", interval(a.multi_tip_ci95)},
              {process_key::reason, a.message.empty() ? json(nullptr) : json(a.message)}};
}

json multi_tip_json(const ProbeResult& p) {
  const MultiTipResult& v = p.vectors;
  const bool ok = v.ok();
  json tips = json::array();
  for (std::size_t k = 0; k < p.geometry.tip_count(); ++k) {
    tips.push_back(json{{"tip", k},
                        {"channel", k < p.channels.size() ? json(p.channels[k]) : json(nullptr)},
                        {"position", vec(p.geometry.positions()[k])},
                        {"leading", k == p.geometry.leading()}});
  }
  json trailing = json::array();
  const auto& order = p.geometry.trailing_tips();
  for (std::size_t k = 0; k < order.size(); ++k) {
    json fates = json::object();
    if (k < p.pairing.fates.size()) {
      for (std::size_t i = 0; i < bubble_fate_count; ++i) fates[std::string(bubble_fate_names[i])] = p.pairing.fates[k][i];
    }
    trailing.push_back(json{{"tip", order[k]}, {"bubbles_by_fate", fates}});
  }
  json intervals = json::array(), rms_intervals = json::array(), tu_intervals = json::array(), stress = json::array();
  for (std::size_t i = 0; i < 3; ++i) {
    intervals.push_back(ci(v.velocity_ci95[i]));
    rms_intervals.push_back(ci(v.velocity_rms_ci95[i]));
    tu_intervals.push_back(ci(v.turbulence_intensity_ci95[i]));
    stress.push_back(vec(v.reynolds_stress[i]));
  }
  auto when_ok = [&](json value) { return ok ? value : json(nullptr); };
  json out{
      {process_key::status, to_string(v.status)},
      {process_key::reason, ok ? json(nullptr) : json(v.message)},
      {"pairing_status", to_string(p.pairing.status)},
      {"velocity_algorithm", to_string(v.options.algorithm)},
      {"record_length", v.record_length},
      {"tips", tips},
      {"trailing_tips", trailing},
      {process_key::velocity, when_ok(vec(v.velocity))},
      {"velocity_ci95", when_ok(intervals)},
      {"speed", when_ok(json(v.speed))},
      {"velocity_rms", when_ok(vec(v.velocity_rms))},
      {"velocity_rms_ci95", when_ok(rms_intervals)},
      {"reynolds_stress", when_ok(stress)},
      {process_key::turbulence_intensity, when_ok(vec(v.turbulence_intensity))},
      {"turbulence_intensity_ci95", when_ok(tu_intervals)},
      {"diameter_front", optional(v.diameter_front)},
      {"diameter_rear", optional(v.diameter_rear)},
      {"interfacial_area", optional(v.interfacial_area)},
      {"interfacial_area_ci95", v.interfacial_area_ci95 ? ci(*v.interfacial_area_ci95) : json(nullptr)},
      {"interfacial_area_paired", optional(v.interfacial_area_paired)},
      {"caution", v.caution.empty() ? json(nullptr) : json(v.caution)},
      {"quality", to_string(p.quality)},
      {"quality_reason", p.quality_reason.empty() ? json(nullptr) : json(p.quality_reason)},
      {"bubbles_total", v.bubbles_total},
      {"bubbles_complete", v.bubbles_complete},
      {"bubbles_accepted", v.bubbles_accepted},
      {"partners_censored", v.partners_censored},
      {"combinations_solved", v.combinations_solved},
      {"combinations_ill_conditioned", v.combinations_ill_conditioned},
      {"combinations_degenerate", v.combinations_degenerate},
      {"roc_passes", v.roc_passes},
  };
  json fates = json::object();
  for (std::size_t i = 0; i < vector_fate_count; ++i) fates[std::string(vector_fate_names[i])] = v.bubbles_by_fate[i];
  out["bubbles_by_fate"] = fates;
  json further = json::array();
  for (const auto& t : p.further_tips) further.push_back(tip_json(t));
  out["further_tips"] = further;
  json pairs = json::array();
  for (const auto& pair : p.pairs) {
    json j{{"tip", pair.tip}, {"channel", pair.channel}, {process_key::dx, pair.dx}, {process_key::dy, pair.dy}};
    if (pair.fscc) j[process_key::fscc] = fscc_json(*pair.fscc);
    if (pair.awcc) j[process_key::awcc] = awcc_json(*pair.awcc);
    pairs.push_back(j);
  }
  out["pairs"] = pairs;
  return out;
}

}  // namespace

namespace {

json quantity_json(const FlowQuantity& q) {
  return json{{"value", optional(q.value)},
              {"ci95", q.ci95 ? ci(*q.ci95) : json(nullptr)},
              {"reason", q.reason.empty() ? json(nullptr) : json(q.reason)},
              {"draws_defined", q.draws_defined}};
}

json depth_json(const CharacteristicDepth& point, const FlowQuantity& depth) {
  json out = quantity_json(depth);
  out["level"] = point.level;
  out["status"] = to_string(point.status);
  out["position"] = optional(point.y);
  if (!point.message.empty()) out["reason"] = point.message;
  return out;
}

json fit_json(const ConcentrationFit& f) {
  json out = quantity_json(f.diffusivity);
  out["residual"] = optional(f.residual);
  out["points"] = f.points;
  out["k_prime"] = f.curve ? json(f.curve->k_prime()) : json(nullptr);
  return out;
}

}  // namespace

json to_json(const ProfileFlowResult& f) {
  json levels = json::array();
  for (const auto& l : f.levels) levels.push_back(depth_json(l.point, l.depth));
  json rows = json::array();
  for (const auto& r : f.rows) {
    rows.push_back(json{{"name", r.name},
                        {"position", r.y},
                        {"void_fraction", r.c},
                        {"velocity", optional(r.u)},
                        {"velocity_source", r.u ? json(to_string(r.u_source)) : json(nullptr)}});
  }
  json power{{"n", quantity_json(f.power_law.n)},
             {"u90", quantity_json(f.power_law.u90)},
             {"residual", optional(f.power_law.residual)},
             {"points", f.power_law.points}};
  json out{{process_key::status, to_string(f.status)},
           {process_key::reason, f.message.empty() ? json(nullptr) : json(f.message)},
           {"notes", f.notes},
           {"invert", to_string(f.options.invert)},
           {"discharge", optional(f.options.discharge)},
           {"chute_angle", optional(f.options.chute_angle)},
           {"draws", f.draws},
           {"seed", f.options.seed},
           {"y90", depth_json(f.y90_point, f.y90)},
           {"levels", levels},
           {"power_law", power},
           {process_key::smooth_chute, fit_json(f.smooth_chute)},
           {process_key::stepped_chute, fit_json(f.stepped_chute)},
           {"rows", rows}};
  // The plain quantities, each from its row of flow_quantity_names.
  for (const auto& q : flow_quantity_names) {
    if (q.plain) out[json::json_pointer(std::string(q.pointer))] = quantity_json(q.of(f));
  }
  return out;
}

json to_json(const ProcessResult& r) {
  json tips = json::array();
  for (const auto& t : r.tips) tips.push_back(tip_json(t));
  json out{
      {process_key::file, r.info.path.string()},
      {"format", r.info.description},
      {process_key::fs, r.info.fs},
      {process_key::samples, r.info.frames},
      {process_key::duration, r.info.fs > 0 ? static_cast<double>(r.info.frames) / r.info.fs : 0.0},
      {process_key::dx, r.dx},
      {process_key::dy, r.dy},
      {process_key::tips, tips},
      {process_key::warnings, warning_texts(r)},
      {process_key::flags, flag_codes(r)},
      {process_key::chord_velocity_source, to_string(r.velocity_source())},
      {"chord_velocity", optional(r.velocity())},
  };
  if (r.fscc) out[process_key::fscc] = fscc_json(*r.fscc);
  if (r.structure) out["structure"] = to_json(*r.structure);
  if (r.spectrum) {
    const auto& v = *r.spectrum;
    const bool ok = v.status == SpectrumStatus::ok;
    out["velocity_spectrum"] = json{{process_key::status, to_string(v.status)},
                                    {process_key::reason, v.message.empty() ? json(nullptr) : json(v.message)},
                                    {"mean_window_duration", ok ? json(v.mean_window_duration) : json(nullptr)},
                                    {"resample_rate", ok ? json(v.resample_rate) : json(nullptr)},
                                    {"resolvable_frequency", ok ? json(v.resolvable_frequency) : json(nullptr)},
                                    {"segments", v.psd.segments},
                                    {"integral_time_scale", optional(v.integral_time_scale)},
                                    {"integral_time_scale_held", optional(v.integral_time_scale_held)},
                                    {"time_scale_ratio", optional(v.time_scale_ratio)},
                                    {"warning", v.warning.empty() ? json(nullptr) : json(v.warning)}};
  }
  if (r.awcc) out[process_key::awcc] = awcc_json(*r.awcc);
  if (r.events) out[process_key::events] = events_json(*r.events);
  if (r.probe) out[process_key::multi_tip] = multi_tip_json(*r.probe);
  out[process_key::sizes] = r.sizes ? sizes_json(*r.sizes) : json(nullptr);
  out[process_key::interfacial_area] = interfacial_area_json(r.interfacial_area);
  return out;
}

std::span<const ProfileColumn> profile_csv_columns() {
  static constexpr ProfileColumn columns[] = {
      {profile_column::file, "", "/file", "the recording's file name"},
      {profile_column::position, "m", "/position", "position of the probe in the profile"},
      {profile_column::void_fraction, "-", "/tips/0/void_fraction", "void fraction c, leading tip"},
      {profile_column::bubble_count_rate, "1/s", "/tips/0/bubble_count_rate", "bubble count rate F, leading tip"},
      {"chord_time_mean", "s", "/tips/0/chord_time_mean", "mean air chord time, leading tip"},
      {"chord_time_median", "s", "/tips/0/chord_time_median", "median air chord time, leading tip"},
      {"threshold", "V", "/tips/0/threshold", "binarisation threshold, leading tip"},
      {"void_fraction_trailing", "-", "/tips/1/void_fraction", "void fraction c, trailing tip"},
      {"bubble_count_rate_trailing", "1/s", "/tips/1/bubble_count_rate", "bubble count rate F, trailing tip"},
      {profile_column::fscc_velocity, "m/s", "/fscc/velocity", "FSCC velocity dx / lag"},
      {"fscc_lag", "s", "/fscc/lag", "lag of the R12 peak"},
      {profile_column::fscc_r12_max, "-", "/fscc/r12_max", "peak cross-correlation R12max"},
      {"fscc_t05", "s", "/fscc/t05", "T05: R11 first at or below 0.5"},
      {"fscc_tau05", "s", "/fscc/tau05", "tau05: half-width of R12 right of its peak"},
      {profile_column::fscc_turbulence_intensity_chanson, "-", "/fscc/turbulence_intensity_chanson",
       "Chanson's Tu from T05 and tau05"},
      {"sauter_diameter", "m", "/tips/0/sauter_diameter", "Sauter diameter d32 = 1.5 u c / F (droplets above c = 0.5: 1.5 u (1 - c) / F)"},
      {"fscc_reason", "", "/fscc/reason", "why FSCC has no velocity"},
      {profile_column::awcc_velocity, "m/s", "/awcc/velocity", "AWCC mean interfacial velocity"},
      {"awcc_velocity_rms", "m/s", "/awcc/velocity_rms", "AWCC velocity fluctuation u_rms"},
      {profile_column::awcc_turbulence_intensity, "-", "/awcc/turbulence_intensity", "AWCC turbulence intensity Tu = u_rms / u"},
      {profile_column::awcc_windows_accepted, "-", "/awcc/windows_accepted", "AWCC windows accepted"},
      {profile_column::awcc_windows_total, "-", "/awcc/windows_total", "AWCC windows formed"},
      {profile_column::awcc_reason, "", "/awcc/reason", "why AWCC has no figures"},
      {profile_column::fscc_status, "", "/fscc/status", "FSCC status"},
      {profile_column::awcc_status, "", "/awcc/status", "AWCC status"},
      {profile_column::dx, "m", "/dx", "streamwise tip separation"},
      {profile_column::dy, "m", "/dy", "lateral tip separation"},
      {profile_column::np, "-", "/awcc/options/np", "particles per AWCC window"},
      {profile_column::awcc_filter_a, "-", "/awcc/options/filter_a", "AWCC correlation/SPR filter A"},
      {profile_column::awcc_roc, "", "/awcc/options/roc", "AWCC robust outlier cutoff"},
      {profile_column::awcc_weighting, "", "/awcc/options/weighting", "AWCC window weighting"},
      {profile_column::awcc_signal, "", "/awcc/options/signal", "signal AWCC correlated"},
      {profile_column::awcc_subsample, "", "/awcc/options/subsample", "AWCC peak refinement"},
      {profile_column::fs, "Hz", "/fs", "sampling rate"},
      {profile_column::duration, "s", "/duration", "record duration"},
      {profile_column::awcc_quality, "", "/awcc/quality", "AWCC quality level: ok, low or insufficient"},
      {profile_column::awcc_quality_reason, "", "/awcc/quality_reason", "why the quality is not ok"},
      {profile_column::void_fraction_ci95_lower, "-", "/tips/0/void_fraction_ci95/0", "void fraction, 95 % interval, lower"},
      {profile_column::void_fraction_ci95_upper, "-", "/tips/0/void_fraction_ci95/1", "void fraction, 95 % interval, upper"},
      {profile_column::bubble_count_rate_ci95_lower, "1/s", "/tips/0/bubble_count_rate_ci95/0", "bubble count rate, 95 % interval, lower"},
      {profile_column::bubble_count_rate_ci95_upper, "1/s", "/tips/0/bubble_count_rate_ci95/1", "bubble count rate, 95 % interval, upper"},
      {profile_column::fscc_velocity_ci95_lower, "m/s", "/fscc/velocity_ci95/0", "FSCC velocity, 95 % sampling interval, lower"},
      {profile_column::fscc_velocity_ci95_upper, "m/s", "/fscc/velocity_ci95/1", "FSCC velocity, 95 % sampling interval, upper"},
      {profile_column::awcc_velocity_ci95_lower, "m/s", "/awcc/velocity_ci95/0", "AWCC velocity, 95 % interval, lower"},
      {profile_column::awcc_velocity_ci95_upper, "m/s", "/awcc/velocity_ci95/1", "AWCC velocity, 95 % interval, upper"},
      {"awcc_velocity_rms_ci95_lower", "m/s", "/awcc/velocity_rms_ci95/0", "u_rms, 95 % interval, lower"},
      {"awcc_velocity_rms_ci95_upper", "m/s", "/awcc/velocity_rms_ci95/1", "u_rms, 95 % interval, upper"},
      {"awcc_turbulence_intensity_ci95_lower", "-", "/awcc/turbulence_intensity_ci95/0", "AWCC Tu, 95 % interval, lower"},
      {"awcc_turbulence_intensity_ci95_upper", "-", "/awcc/turbulence_intensity_ci95/1", "AWCC Tu, 95 % interval, upper"},
      {profile_column::chord_velocity_source, "", "/chord_velocity_source", "the velocity of the chord lengths and d32"},
      {"pdp_version", "", "", "pdp version (the provenance's)"},
      {profile_column::warnings, "", "/warnings", "every warning of the row, with advice (the reader's, FSCC's, the time scale's, the methods' consistency)"},
      {profile_column::flags, "", "/flags", "the warnings' flag codes, in the same order"},
      {profile_column::awcc_probe_corrected, "", "/awcc/probe_corrected", "bubble-probe interaction correction applied"},
      {"awcc_velocity_measured", "m/s", "/awcc/velocity_measured", "AWCC velocity before the probe correction"},
      {"awcc_velocity_rms_measured", "m/s", "/awcc/velocity_rms_measured", "u_rms before the probe correction"},
      {"awcc_turbulence_intensity_measured", "-", "/awcc/turbulence_intensity_measured", "Tu before the probe correction"},
      {"velocity_integral_time_scale", "s", "/velocity_spectrum/integral_time_scale", "integral time scale T_u of AWCC's velocity series"},
      {"velocity_time_scale_ratio", "-", "/velocity_spectrum/time_scale_ratio", "T_u / T_W (below 2: AWCC's Tu underestimated)"},
      {profile_column::events_velocity, "m/s", "/events/velocity", "event detection's mean velocity (method events)"},
      {"events_velocity_ci95_lower", "m/s", "/events/velocity_ci95/0", "event detection velocity, 95 % interval, lower"},
      {"events_velocity_ci95_upper", "m/s", "/events/velocity_ci95/1", "event detection velocity, 95 % interval, upper"},
      {"events_turbulence_intensity", "-", "/events/turbulence_intensity", "event detection's Tu"},
      {profile_column::events_quality, "", "/events/quality", "event detection's quality: ok, low or insufficient"},
      {"events_bubbles_paired", "-", "/events/bubbles_paired", "bubbles paired by event detection"},
      {profile_column::multi_tip_status, "", "/multi_tip/status", "multi-tip statistics: ok or too_few_bubbles"},
      {profile_column::multi_tip_quality, "", "/multi_tip/quality", "multi-tip quality: ok, low or insufficient"},
      {"multi_tip_velocity_x", "m/s", "/multi_tip/velocity/0", "multi-tip mean velocity vector, x (streamwise)"},
      {"multi_tip_velocity_y", "m/s", "/multi_tip/velocity/1", "multi-tip mean velocity vector, y"},
      {"multi_tip_velocity_z", "m/s", "/multi_tip/velocity/2", "multi-tip mean velocity vector, z"},
      {"multi_tip_turbulence_intensity_x", "-", "/multi_tip/turbulence_intensity/0", "multi-tip Tu_x"},
      {"multi_tip_turbulence_intensity_y", "-", "/multi_tip/turbulence_intensity/1", "multi-tip Tu_y"},
      {"multi_tip_turbulence_intensity_z", "-", "/multi_tip/turbulence_intensity/2", "multi-tip Tu_z"},
      {"multi_tip_diameter", "m", "/multi_tip/diameter_front", "multi-tip mean bubble diameter (front interfaces)"},
      {"multi_tip_interfacial_area", "1/m", "/multi_tip/interfacial_area", "multi-tip interfacial area concentration"},
      {"multi_tip_bubbles_accepted", "-", "/multi_tip/bubbles_accepted", "bubbles with an accepted velocity vector"},
      {profile_column::sizes_status, "", "/sizes/status", "size distribution: ok, or why none (docs/output.md)"},
      {"sizes_d10", "m", "/sizes/d10", "number mean diameter d10 of the inverted size distribution"},
      {"sizes_d32", "m", "/sizes/d32", "Sauter diameter d32 of the inverted size distribution"},
      {"sizes_median", "m", "/sizes/median", "number median diameter of the inverted size distribution"},
      {"interfacial_area", "1/m", "/interfacial_area/value", "interfacial area concentration (interfacial_area_source's)"},
      {"interfacial_area_ci95_lower", "1/m", "/interfacial_area/ci95/0", "interfacial area, 95 % interval, lower"},
      {"interfacial_area_ci95_upper", "1/m", "/interfacial_area/ci95/1", "interfacial area, 95 % interval, upper"},
      {profile_column::interfacial_area_source, "", "/interfacial_area/source",
       "which estimate interfacial_area is: dual_tip (4 F / u = 6 c / d32) or multi_tip"},
      {profile_column::awcc_time_scale_ratio, "-", "/awcc/time_scale_ratio",
       "AWCC's T_u / T_W capped at 20: the bias correction's time-scale feature"},
      {"awcc_weighting_gap", "-", "/awcc/weighting_gap/value",
       "AWCC's weighting gap g = u_unweighted / u_weighted - 1 (near 0 for bubbles arriving in time)"},
      {"awcc_weighting_gap_ci95_lower", "-", "/awcc/weighting_gap/ci95/0", "weighting gap, 95 % interval, lower"},
      {"awcc_weighting_gap_ci95_upper", "-", "/awcc/weighting_gap/ci95/1", "weighting gap, 95 % interval, upper"},
      {profile_column::awcc_turbulence_measured, "", "/awcc/turbulence_measured",
       "whether AWCC's Tu is measured (off: every accepted window at one lag, Tu empty)"},
      {profile_column::awcc_windows_at_least_lag, "-", "/awcc/windows_at_least_lag",
       "AWCC accepted windows at the least lag of the velocity range"},
      {profile_column::awcc_windows_at_greatest_lag, "-", "/awcc/windows_at_greatest_lag",
       "AWCC accepted windows at the greatest lag of the velocity range"},
  };
  return columns;
}

std::string profile_csv_header() {
  std::string out;
  for (const auto& c : profile_csv_columns()) out += (out.empty() ? "" : ",") + std::string(c.name);
  return out;
}

std::string profile_csv_row(const ProcessResult& r, const std::optional<double>& position) {
  const auto& lead = r.tips.at(0).phase;
  const auto& trail = r.tips.at(1).phase;
  const auto& f = r.fscc;
  const auto& a = r.awcc;
  const bool fscc_ok = f && f->ok();
  const bool awcc_ok = a && a->ok();
  auto number = [](double v) { return csv_number(v); };
  std::string out = fmt::format(
      "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", csv_cell(r.info.path.filename().string()),
      csv_number(position), number(lead.void_fraction), number(lead.bubble_count_rate),
      number(lead.air_chord_time.mean), number(lead.air_chord_time.median), number(r.tips[0].threshold.threshold),
      number(trail.void_fraction), number(trail.bubble_count_rate),
      csv_number(fscc_ok ? std::optional(f->velocity) : std::nullopt),
      csv_number(f ? std::optional(f->lag) : std::nullopt), csv_number(f ? std::optional(f->r12_max) : std::nullopt),
      csv_number(f ? f->t05 : std::nullopt), csv_number(f ? f->tau05 : std::nullopt),
      csv_number(f ? f->turbulence_intensity_chanson : std::nullopt), csv_number(lead.sauter_diameter),
      csv_cell(f && !f->ok() ? f->message : std::string()));
  // The spread and Tu where they are measured (AwccResult::turbulence_measured).
  const bool awcc_spread = awcc_ok && a->turbulence_measured;
  out += fmt::format(",{},{},{},{},{},{}", csv_number(awcc_ok ? std::optional(a->velocity) : std::nullopt),
                     csv_number(awcc_spread ? std::optional(a->velocity_rms) : std::nullopt),
                     csv_number(awcc_spread ? std::optional(a->turbulence_intensity) : std::nullopt),
                     a ? std::to_string(a->windows_accepted) : std::string(),
                     a ? std::to_string(a->windows_total) : std::string(),
                     csv_cell(a && !a->ok() ? a->message : std::string()));
  out += fmt::format(",{},{},{},{}", f ? to_string(f->status) : "", a ? to_string(a->status) : "", number(r.dx),
                     number(r.dy));
  if (a) {
    const auto& o = a->options;
    out += fmt::format(",{},{},{},{},{},{}", o.np, number(o.filter_a), switch_text(o.roc), to_string(o.weighting),
                       to_string(o.signal), to_string(o.subsample));
  } else {
    out += ",,,,,,";
  }
  const double duration = r.info.fs > 0 ? static_cast<double>(r.info.frames) / r.info.fs : 0.0;
  auto interval = [&](bool known, const Interval95& i) {
    return known ? fmt::format("{},{}", number(i.lower), number(i.upper)) : std::string(",");
  };
  const bool fscc_interval = fscc_ok && f->velocity_ci95;
  out += fmt::format(",{},{},{},{},{},{},{},{},{},{},{},{}", number(r.info.fs), number(duration),
                     a ? to_string(a->quality) : "", csv_cell(a ? a->quality_reason : std::string()),
                     interval(true, lead.void_fraction_ci95), interval(true, lead.bubble_count_rate_ci95),
                     interval(fscc_interval, fscc_interval ? *f->velocity_ci95 : Interval95{}),
                     interval(awcc_ok, a ? a->velocity_ci95 : Interval95{}),
                     interval(awcc_spread, a ? a->velocity_rms_ci95 : Interval95{}),
                     interval(awcc_spread, a ? a->turbulence_intensity_ci95 : Interval95{}), to_string(r.velocity_source()),
                     version);
  out += "," + csv_cell(joined(warning_texts(r))) + "," + csv_cell(joined(flag_codes(r)));
  const bool corrected = awcc_ok && a->probe_corrected;
  out += fmt::format(",{},{},{},{}", a ? switch_text(a->probe_corrected) : "",
                     csv_number(corrected ? std::optional(a->velocity_measured) : std::nullopt),
                     csv_number(corrected ? std::optional(a->velocity_rms_measured) : std::nullopt),
                     csv_number(corrected ? std::optional(a->turbulence_intensity_measured) : std::nullopt));
  const bool series = r.spectrum && r.spectrum->status == SpectrumStatus::ok;
  out += fmt::format(",{},{}", csv_number(series ? r.spectrum->integral_time_scale : std::nullopt),
                     csv_number(series ? r.spectrum->time_scale_ratio : std::nullopt));
  const auto& e = r.events;
  const bool events_ok = e && e->ok();
  auto if_events = [&](double v) { return csv_number(events_ok ? std::optional(v) : std::nullopt); };
  out += fmt::format(",{},{},{},{},{},{}", if_events(e ? e->velocity : 0.0),
                     if_events(e ? e->velocity_ci95.lower : 0.0), if_events(e ? e->velocity_ci95.upper : 0.0),
                     csv_number(events_ok && e->turbulence_measured ? std::optional(e->turbulence_intensity) : std::nullopt),
                     e ? to_string(e->quality) : "",
                     e ? std::to_string(e->bubbles_paired) : std::string());
  if (r.probe) {
    const auto& v = r.probe->vectors;
    auto if_ok = [&](double x) { return csv_number(v.ok() ? std::optional(x) : std::nullopt); };
    out += fmt::format(",{},{},{},{},{},{},{},{},{},{},{}", to_string(v.status), to_string(r.probe->quality),
                       if_ok(v.velocity[0]),
                       if_ok(v.velocity[1]), if_ok(v.velocity[2]), if_ok(v.turbulence_intensity[0]),
                       if_ok(v.turbulence_intensity[1]), if_ok(v.turbulence_intensity[2]), csv_number(v.diameter_front),
                       csv_number(v.interfacial_area), v.bubbles_accepted);
  } else {
    out += ",,,,,,,,,,,";
  }
  const bool sized = r.sizes && r.sizes->has_distribution();
  auto size = [&](double SizeDistribution::* m) {
    return csv_number(sized ? std::optional(r.sizes->distribution.*m) : std::nullopt);
  };
  const auto& area = r.interfacial_area;
  const auto area_ci = area.ci95();
  out += fmt::format(",{},{},{},{},{},{},{},{}", r.sizes ? to_string(r.sizes->status) : "", size(&SizeDistribution::d10),
                     size(&SizeDistribution::d32), size(&SizeDistribution::median), csv_number(area.value()),
                     csv_number(area_ci ? std::optional(area_ci->lower) : std::nullopt),
                     csv_number(area_ci ? std::optional(area_ci->upper) : std::nullopt),
                     area.source ? to_string(*area.source) : "");
  out += "," + csv_number(awcc_ok ? a->time_scale_ratio : std::nullopt);
  const auto* gap = awcc_ok && a->weighting_gap ? &*a->weighting_gap : nullptr;
  out += fmt::format(",{},{},{}", csv_number(gap ? std::optional(gap->value) : std::nullopt),
                     csv_number(gap ? std::optional(gap->ci95.lower) : std::nullopt),
                     csv_number(gap ? std::optional(gap->ci95.upper) : std::nullopt));
  out += fmt::format(",{},{},{}", awcc_ok ? switch_text(a->turbulence_measured) : "",
                     a ? std::to_string(a->windows_at_least_lag) : std::string(),
                     a ? std::to_string(a->windows_at_greatest_lag) : std::string());
  return out;
}

std::string correlation_functions_csv(const std::vector<const ProcessResult*>& results) {
  std::string out = "file,lag_s,r11,r12\n";
  for (const auto* r : results) {
    if (!r->fscc) continue;
    const auto& f = *r->fscc;
    const auto n11 = static_cast<std::int64_t>(f.r11.size()), n12 = static_cast<std::int64_t>(f.r12.size());
    if (n11 == 0 && n12 == 0) continue;
    const std::int64_t first = std::min(f.r11_first_lag, f.r12_first_lag);
    const std::int64_t last = std::max(f.r11_first_lag + n11, f.r12_first_lag + n12) - 1;
    const std::string file = csv_cell(r->info.path.filename().string());
    for (std::int64_t k = first; k <= last; ++k) {
      auto cell = [k](const std::vector<double>& v, std::int64_t k0) {
        const std::int64_t j = k - k0;
        // Shortest text that reads back as the same double: the functions are compared digit for digit.
        return j >= 0 && j < static_cast<std::int64_t>(v.size()) ? fmt::format("{}", v[static_cast<std::size_t>(j)])
                                                                 : std::string();
      };
      out += fmt::format("{},{},{},{}\n", file, csv_number(static_cast<double>(k) / r->info.fs), cell(f.r11, f.r11_first_lag),
                         cell(f.r12, f.r12_first_lag));
    }
  }
  return out;
}

std::string velocity_spectrum_csv(const std::vector<const ProcessResult*>& results) {
  std::string out = "file,quantity,x,value,below_resolvable_frequency\n";
  for (const auto* r : results) {
    if (!r->spectrum || r->spectrum->status != SpectrumStatus::ok) continue;
    const auto& v = *r->spectrum;
    const std::string file = csv_cell(r->info.path.filename().string());
    for (std::size_t k = 0; k < v.psd.frequency.size(); ++k) {
      out += fmt::format("{},psd,{},{},{}\n", file, csv_number(v.psd.frequency[k]), csv_number(v.psd.density[k]),
                         v.psd.frequency[k] < v.resolvable_frequency ? 1 : 0);
    }
    for (std::size_t k = 0; k < v.autocorrelation.size(); ++k) {
      out += fmt::format("{},autocorrelation,{},{},\n", file, csv_number(static_cast<double>(k) / v.resample_rate),
                         csv_number(v.autocorrelation[k]));
    }
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> structure_csv_tables(
    const std::vector<const ProcessResult*>& results, const std::vector<std::optional<double>>& positions) {
  std::string voltage = "file,position,tip,v_lower_V,v_upper_V,fraction\n";
  std::string chords = "file,position,basis,unit,bin_lower,bin_upper,air_count,air_fraction,water_count,water_fraction\n";
  std::string clusters =
      "file,position,basis,unit,regime,status,criterion,criterion_value,n_particles,n_in_clusters,pct_in_clusters,"
      "n_clusters,clusters_per_s,mean_particles_per_cluster,mean_chord_in_cluster,ratio_cluster_chord_to_mean_chord,"
      "ratio_lead_to_cluster_mean_chord,reason\n";
  std::string sizes = "file,position,basis,criterion,particles,count,fraction\n";
  std::string classes =
      "file,position,basis,unit,regime,status,class_lower,class_upper,particles,intervals,excess_first_bin,"
      "excess_first_bin_se,reason\n";
  std::string arrivals = "file,position,basis,class_lower,class_upper,bin_lower_s,bin_upper_s,count,pdf,reference\n";
  auto unit = [](ChordBasis b) { return b == ChordBasis::length ? "m" : "s"; };
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto* r = results[i];
    if (!r->structure) continue;
    const auto& s = *r->structure;
    const std::string where = fmt::format("{},{}", csv_cell(r->info.path.filename().string()), csv_number(positions[i]));
    for (const auto& [tip, pdf] : {std::pair{"leading", &s.voltage_leading}, std::pair{"trailing", &s.voltage_trailing}}) {
      if (!*pdf) continue;
      const auto& p = **pdf;
      for (std::size_t k = 0; k < p.fraction.size(); ++k) {
        voltage += fmt::format("{},{},{},{},{}\n", where, tip, std::isfinite(p.lower[k]) ? csv_number(p.lower[k]) : std::string(),
                               csv_number(p.upper[k]), csv_number(p.fraction[k]));
      }
    }
    for (const auto* pdf : {&s.chord_time, s.chord_length ? &*s.chord_length : nullptr}) {
      if (!pdf) continue;
      for (std::size_t k = 0; k < pdf->air_counts.size(); ++k) {
        const bool overflow = k + 1 == pdf->air_counts.size();
        chords += fmt::format("{},{},{},{},{},{},{},{},{}\n", where, to_string(pdf->basis), unit(pdf->basis),
                              csv_number(pdf->lower_edge(k)), overflow ? std::string() : csv_number(pdf->lower_edge(k + 1)),
                              pdf->air_counts[k], csv_number(pdf->air_fraction[k]), pdf->water_counts[k],
                              csv_number(pdf->water_fraction[k]));
      }
    }
    for (const auto* c : {&s.clusters_time, &s.clusters_length}) {
      const std::string head = fmt::format("{},{},{},{},{}", where, to_string(c->basis), unit(c->basis), to_string(c->regime),
                                           to_string(c->status));
      if (c->criteria.empty()) {
        clusters += fmt::format("{},,,,,,,,,,,,{}\n", head, csv_cell(c->message));
        continue;
      }
      for (const auto& k : c->criteria) {
        clusters += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},\n", head, to_string(k.criterion),
                                csv_number(k.criterion_value), k.particles, k.in_clusters,
                                csv_number(k.percent_in_clusters), k.clusters, csv_number(k.clusters_per_second),
                                csv_number(k.mean_particles_per_cluster), csv_number(k.mean_chord_in_cluster),
                                csv_number(k.ratio_cluster_chord_to_mean_chord),
                                csv_number(k.ratio_lead_to_cluster_mean_chord));
        for (std::size_t j = 0; j < k.size_counts.size(); ++j) {
          sizes += fmt::format("{},{},{},{},{},{}\n", where, to_string(c->basis), to_string(k.criterion),
                               j + 1 == k.size_counts.size() ? std::string("21+") : std::to_string(j + 2),
                               k.size_counts[j], k.size_pdf ? csv_number((*k.size_pdf)[j]) : std::string());
        }
      }
    }
    for (const auto* a : {&s.arrivals_time, &s.arrivals_length}) {
      const std::string head = fmt::format("{},{},{},{},{}", where, to_string(a->basis), unit(a->basis), to_string(a->regime),
                                           to_string(a->status));
      if (a->classes.empty()) {
        classes += fmt::format("{},,,,,,,{}\n", head, csv_cell(a->message));
        continue;
      }
      for (const auto& c : a->classes) {
        const std::string bounds = fmt::format("{},{}", csv_number(c.lower), csv_number(c.upper));
        classes += fmt::format("{},{},{},{},{},{},\n", head, bounds, c.particles, c.intervals,
                               csv_number(c.excess_first_bin), csv_number(c.excess_first_bin_se));
        for (std::size_t m = 0; m < c.counts.size(); ++m) {
          const bool overflow = m + 1 == c.counts.size();
          arrivals += fmt::format("{},{},{},{},{},{},{},{}\n", where, to_string(a->basis), bounds,
                                  csv_number(static_cast<double>(m) * a->bin_width),
                                  overflow ? std::string() : csv_number(static_cast<double>(m + 1) * a->bin_width),
                                  c.counts[m], c.pdf.empty() ? std::string() : csv_number(c.pdf[m]),
                                  c.reference.empty() ? std::string() : csv_number(c.reference[m]));
        }
      }
    }
  }
  return {{"_voltage_pdf.csv", voltage},   {"_chord_pdf.csv", chords},          {"_clusters.csv", clusters},
          {"_cluster_sizes.csv", sizes},   {"_arrival_classes.csv", classes},   {"_arrivals.csv", arrivals}};
}

std::string ProcessResult::report() const {
  std::string out;
  auto line = [&out](const std::string& s) { out += s + "\n"; };
  line(fmt::format("{}: {}, {} channels, {:.6g} Hz, {} samples ({:.3f} s)", info.path.string(), info.description,
                   info.channels, info.fs, info.frames, info.fs > 0 ? static_cast<double>(info.frames) / info.fs : 0.0));
  const char* names[2] = {"leading", "trailing"};
  for (std::size_t i = 0; i < tips.size(); ++i) {
    const auto& t = tips[i];
    const auto& p = t.phase;
    // Volts where the file states them; else the file's own units (a WAV's
    // normalised samples, counts without their scale), said so.
    const char* unit = info.volts_known ? " V" : "";
    line(fmt::format("  {} tip (channel {}{}): threshold {:.4f}{} ({}{}), air {:.4f}{}, water {:.4f}{}{}", names[i % 2],
                     t.channel, t.name.empty() ? std::string() : fmt::format(", '{}'", t.name), t.threshold.threshold,
                     unit, to_string(t.threshold.rule), t.threshold.binary_input ? ", binary input" : "",
                     t.threshold.air_level, unit, t.threshold.water_level, unit,
                     info.volts_known ? "" : " (the file's units, not volts: it states no volts per count)"));
    line(fmt::format("    void fraction        {:.5f}  (95 % CI {:.5f} - {:.5f})", p.void_fraction,
                     p.void_fraction_ci95.lower, p.void_fraction_ci95.upper));
    line(fmt::format("    {:<20} {:.3f} /s  (95 % CI {:.3f} - {:.3f}), {} complete chords",
                     fmt::format("{} count rate", dispersed_particle(p.void_fraction)), p.bubble_count_rate, p.bubble_count_rate_ci95.lower, p.bubble_count_rate_ci95.upper,
                     p.air_chord_time.count));
    line(fmt::format("    air chord time       mean {:.4f} ms, median {:.4f} ms, std {:.4f} ms", p.air_chord_time.mean * 1e3,
                     p.air_chord_time.median * 1e3, p.air_chord_time.std * 1e3));
    line(fmt::format("    water chord time     mean {:.4f} ms, median {:.4f} ms", p.water_chord_time.mean * 1e3,
                     p.water_chord_time.median * 1e3));
    if (p.air_chord_length) {
      line(fmt::format("    air chord length     mean {:.4f} mm, median {:.4f} mm", p.air_chord_length->mean * 1e3,
                       p.air_chord_length->median * 1e3));
    }
    if (p.sauter_diameter) {
      line(fmt::format("    Sauter diameter d32  {:.4f} mm{}", *p.sauter_diameter * 1e3,
                       p.void_fraction > 0.5 ? " (droplets: 1.5 u (1 - c) / F)" : ""));
    }
    if (!t.threshold.note.empty()) line("    note: " + t.threshold.note);
    if (p.status != PhaseStatus::ok) line("    note: " + p.message);
  }
  if (fscc) {
    const auto& f = *fscc;
    if (f.ok()) {
      std::string interval;
      if (f.velocity_ci95) {
        interval = fmt::format("95 % sampling interval {:.4f} - {:.4f}", f.velocity_ci95->lower, f.velocity_ci95->upper);
      } else if (f.interval_segments < fscc_interval_segments_min) {
        interval = fmt::format("no sampling interval: {} of {} segments hold a peak", f.interval_segments,
                               fscc_interval_segments);
      } else {
        interval = "no sampling interval: the segments' peak lags scatter to lag 0";
      }
      line(fmt::format("  FSCC: velocity {:.4f} m/s ({}), dx {:.3f} mm / lag {:.4f} ms, R12max {:.4f}", f.velocity,
                       interval, dx * 1e3, f.lag * 1e3, f.r12_max));
    } else {
      line(fmt::format("  FSCC: velocity undefined: {}", f.message));
    }
    auto ms = [](const std::optional<double>& v) { return v ? fmt::format("{:.4f} ms", *v * 1e3) : std::string("n/a"); };
    line(fmt::format("        T05 {}, tau05 {}, Txx {}, Txy {}", ms(f.t05), ms(f.tau05), ms(f.txx), ms(f.txy)));
    line(fmt::format("        R11 zero {}, R12 zero {} (correlating {} signals, {} segment{})", ms(f.t_r11_zero),
                     ms(f.t_r12_zero), to_string(f.signal), f.segments_used, f.segments_used == 1 ? "" : "s"));
    line(fmt::format("        Chanson turbulence intensity {}",
                     f.turbulence_intensity_chanson ? fmt::format("{:.4f}", *f.turbulence_intensity_chanson)
                                                    : std::string("n/a")));
    if (!f.note.empty()) line("        note: " + f.note);
  }
  if (awcc) {
    const auto& a = *awcc;
    if (a.ok() && !a.turbulence_measured) {
      line(fmt::format("  AWCC: velocity {:.4f} m/s (bounded by the lag's resolution: {:.4f} - {:.4f}), Tu not "
                       "measured (every window at one lag)",
                       a.velocity, a.velocity_ci95.lower, a.velocity_ci95.upper));
    } else if (a.ok()) {
      line(fmt::format("  AWCC: velocity {:.4f} m/s (95 % sampling interval {:.4f} - {:.4f}), u_rms {:.4f} m/s, Tu "
                       "{:.4f} ({:.4f} - {:.4f})",
                       a.velocity, a.velocity_ci95.lower, a.velocity_ci95.upper, a.velocity_rms,
                       a.turbulence_intensity, a.turbulence_intensity_ci95.lower, a.turbulence_intensity_ci95.upper));
    } else {
      line(fmt::format("  AWCC: no velocity: {}", a.message));
    }
    if (a.probe_corrected && a.ok()) {
      line(fmt::format("        bubble-probe corrected (measured: velocity {:.4f} m/s, u_rms {:.4f} m/s, Tu {:.4f}); {} "
                       "windows failed the correction, {} not bubbly (as measured)",
                       a.velocity_measured, a.velocity_rms_measured, a.turbulence_intensity_measured,
                       a.count(WindowFate::correction), a.windows_not_bubbly));
    }
    line(fmt::format("        quality {}{}", to_string(a.quality),
                     a.quality == AwccQuality::low ? ": " + a.quality_reason : std::string()));
    line(fmt::format("        windows {} accepted of {} (rejected: {} correlation, {} lag, {} outlier cutoff, {} "
                     "constant{})",
                     a.windows_accepted, a.windows_total, a.count(WindowFate::correlation),
                     a.count(WindowFate::lag), a.count(WindowFate::roc), a.count(WindowFate::constant),
                     a.count(WindowFate::too_short) ? fmt::format(", {} too short", a.count(WindowFate::too_short))
                                                    : std::string()));
    if (a.ok() && a.weighting_gap) {
      const auto& g = *a.weighting_gap;
      line(fmt::format("        weighting gap g {:+.4f} (95 % {:+.4f} to {:+.4f}); bubbles arriving in time allow up "
                       "to {:.4f}{}",
                       g.value, g.ci95.lower, g.ci95.upper, g.allowance,
                       g.along_flow ? ": they look spaced along the flow (flag arrivals_along_flow)" : ""));
    }
  }
  if (events) {
    const auto& e = *events;
    if (e.ok() && !e.turbulence_measured) {
      line(fmt::format("  events ({} pairing): velocity {:.4f} m/s, Tu not measured (every bubble at one lag); d32 "
                       "{:.3f} mm from each bubble's own velocity",
                       to_string(e.options.pairing), e.velocity, e.sauter_diameter * 1e3));
    } else if (e.ok()) {
      line(fmt::format("  events ({} pairing): velocity {:.4f} m/s (95 % sampling interval {:.4f} - {:.4f}), u_rms "
                       "{:.4f} m/s, Tu {:.4f} ({:.4f} - {:.4f}); d32 {:.3f} mm from each bubble's own velocity",
                       to_string(e.options.pairing), e.velocity, e.velocity_ci95.lower, e.velocity_ci95.upper,
                       e.velocity_rms, e.turbulence_intensity, e.turbulence_intensity_ci95.lower,
                       e.turbulence_intensity_ci95.upper, e.sauter_diameter * 1e3));
    } else {
      line(fmt::format("  events ({} pairing): no velocity: {}", to_string(e.options.pairing), e.message));
    }
    std::string fates;
    for (std::size_t i = 1; i < bubble_fate_count; ++i) {
      if (e.bubbles_by_fate[i] > 0) fates += fmt::format(", {} {}", e.bubbles_by_fate[i], bubble_fate_names[i]);
    }
    line(fmt::format("        quality {}{}", to_string(e.quality),
                     e.quality_reason.empty() ? std::string() : ": " + e.quality_reason));
    line(fmt::format("        bubbles {} paired of {} complete ({} in all{})", e.bubbles_paired, e.bubbles_complete,
                     e.bubbles_total, fates));
  }
  if (probe) {
    const auto& p = *probe;
    std::string tips_text;
    for (std::size_t k = 0; k < p.geometry.tip_count(); ++k) {
      tips_text += fmt::format("{}{} (channel {})", k == 0 ? "" : ", ", p.geometry.tip_name(k),
                               k < p.channels.size() ? p.channels[k] : -1);
    }
    line("  multi-tip probe: " + tips_text);
    line(fmt::format("    quality {}{}", to_string(p.quality),
                     p.quality_reason.empty() ? std::string() : ": " + p.quality_reason));
    for (const auto& t : p.further_tips) {
      line(fmt::format("    tip of channel {}: void fraction {:.5f}, bubble count rate {:.3f} /s", t.channel,
                       t.phase.void_fraction, t.phase.bubble_count_rate));
    }
    std::string text = p.vectors.report();
    for (std::size_t from = 0; from < text.size();) {
      const auto end = std::min(text.find('\n', from), text.size());
      line("    " + text.substr(from, end - from));
      from = end + 1;
    }
    for (const auto& pair : p.pairs) {
      line(fmt::format("    leading tip with tip {} (dx {:.3f} mm): FSCC {}, AWCC {}", pair.tip, pair.dx * 1e3,
                       pair.fscc && pair.fscc->ok() ? fmt::format("{:.4f} m/s", pair.fscc->velocity)
                                                    : std::string("no velocity"),
                       pair.awcc && pair.awcc->ok() ? fmt::format("{:.4f} m/s", pair.awcc->velocity)
                                                    : std::string("no velocity")));
    }
  }
  if ((fscc && fscc->ok() && fscc->velocity_ci95) || (awcc && awcc->ok())) line("  " + std::string(sampling_intervals_only));
  if (structure) {
    const auto& st = *structure;
    line(fmt::format("  structure of the leading tip ({} conventions): {} bubbles, {} regime", st.felder_defects ? "Felder's" : "default",
                     st.bubbles_used, to_string(st.clusters_time.regime)));
    for (const auto* c : {&st.clusters_time, &st.clusters_length}) {
      if (c->status != ClusterStatus::ok) {
        line(fmt::format("    clusters by {}: {}", to_string(c->basis), c->message));
        continue;
      }
      std::string counts, shares;
      for (const auto& k : c->criteria) {
        counts += fmt::format("{}{}", counts.empty() ? "" : " / ", k.clusters);
        shares += fmt::format("{}{:.1f}", shares.empty() ? "" : " / ", k.percent_in_clusters);
      }
      line(fmt::format("    clusters by {} (median / constant / near-wake): {} clusters, {} % of particles in them",
                       to_string(c->basis), counts, shares));
    }
    for (const auto* a : {&st.arrivals_time, &st.arrivals_length}) {
      if (a->status != ClusterStatus::ok) continue;
      std::string excess;
      for (const auto& k : a->classes) {
        if (!k.excess_first_bin) continue;
        excess += fmt::format("{}{:.2f} +/- {:.2f}", excess.empty() ? "" : ", ", *k.excess_first_bin, *k.excess_first_bin_se);
      }
      if (!excess.empty()) {
        line(fmt::format("    arrivals by {}: observed / random intervals in the first bin, per class: {}",
                         to_string(a->basis), excess));
      }
    }
  }
  if (spectrum && spectrum->status == SpectrumStatus::ok) {
    line(fmt::format("  velocity series: integral time scale {}, mean window {:.2f} ms (ratio {}); spectrum resolvable "
                     "below {:.1f} Hz",
                     spectrum->integral_time_scale ? fmt::format("{:.2f} ms", *spectrum->integral_time_scale * 1e3)
                                                   : std::string("n/a"),
                     spectrum->mean_window_duration * 1e3,
                     spectrum->time_scale_ratio ? fmt::format("{:.2f}", *spectrum->time_scale_ratio) : std::string("n/a"),
                     spectrum->resolvable_frequency));
  }
  if (const auto s = velocity_source(); s != VelocitySource::awcc && (awcc || fscc)) {
    line(s == VelocitySource::fscc ? "  chord lengths and d32 use FSCC's velocity (AWCC's is not of quality ok)"
                                   : "  chord lengths and d32: no velocity");
  }
  if (sizes) {
    const std::string text = sizes->report();
    for (std::size_t from = 0; from < text.size();) {
      const auto end = std::min(text.find('\n', from), text.size());
      line("  " + text.substr(from, end - from));
      from = end + 1;
    }
  }
  {
    std::string text = interfacial_area.report();
    if (!text.empty() && text.back() == '\n') text.pop_back();
    line("  " + text);
  }
  for (const auto& w : warnings) line(fmt::format("  warning: {} [{}]", w.text, to_string(w.flag)));
  return out;
}

}  // namespace awcc
