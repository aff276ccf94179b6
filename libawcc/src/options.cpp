#include "awcc/options.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>
#include <stdexcept>
#include <string>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/read_back.hpp"
#include "awcc/units.hpp"

namespace awcc {

namespace {

double quantity(std::string_view text, Dimension d) { return parse_quantity(text, d); }

long long whole(std::string_view text, long long lo, long long hi) { return parse_whole(text, lo, hi); }

template <class E, std::size_t N>
E choice(std::string_view text, const std::array<std::pair<const char*, E>, N>& choices) {
  std::string names;
  for (const auto& [name, value] : choices) {
    if (text == name) return value;
    names += (names.empty() ? "" : " | ") + std::string(name);
  }
  throw std::invalid_argument(fmt::format("'{}' is not one of {}", text, names));
}

template <class E, std::size_t N>
std::string name_of(E value, const std::array<std::pair<const char*, E>, N>& choices) {
  for (const auto& [name, v] : choices)
    if (v == value) return name;
  return "?";
}

// An enum that is also a written result is spelled by its to_string, over the
// values read_back.hpp lists: the option, the files and their read-back share
// one text per value.
template <class E, std::size_t N>
E choice(std::string_view text, const E (&values)[N]) {
  std::string names;
  for (const E v : values) {
    if (text == to_string(v)) return v;
    names += (names.empty() ? "" : " | ") + std::string(to_string(v));
  }
  throw std::invalid_argument(fmt::format("'{}' is not one of {}", text, names));
}

template <class E>
std::string name_of(E value) {
  return std::string(to_string(value));
}

// A switch is written "on"/"off" (switch_text); an option also takes
// true/yes/1 and false/no/0 as aliases of them.
bool on_off(std::string_view text) {
  if (text == switch_text(true) || text == "true" || text == "yes" || text == "1") return true;
  if (text == switch_text(false) || text == "false" || text == "no" || text == "0") return false;
  throw std::invalid_argument(fmt::format("'{}' is not on or off", text));
}

std::pair<std::string_view, std::string_view> pair_of(std::string_view text, const char* example) {
  const auto comma = text.find(',');
  if (comma == std::string_view::npos) throw std::invalid_argument(fmt::format("write two values 'a,b', e.g. {}", example));
  return {text.substr(0, comma), text.substr(comma + 1)};
}

/// Names written back as one comma-separated cell, or what an empty list means.
std::string cells_or(const std::vector<std::string>& names, const char* empty) {
  std::string out;
  for (const auto& c : names) out += (out.empty() ? "" : ",") + c;
  return out.empty() ? std::string(empty) : out;
}

std::string cells_of(const std::vector<int>& values) {
  std::string out;
  for (int v : values) out += (out.empty() ? "" : ",") + std::to_string(v);
  return out;
}

// The recording formats as the registry (awcc/recording.hpp) names them: "auto | sndfile | dat | ...".
const std::string& format_choices() {
  static const std::string choices = [] {
    std::string out(kAutomaticFormat);
    for (auto name : input_formats()) out += " | " + std::string(name);
    return out;
  }();
  return choices;
}
std::string input_format(std::string_view text) {
  const auto names = input_formats();
  if (text != kAutomaticFormat && std::find(names.begin(), names.end(), text) == names.end()) {
    throw std::invalid_argument(fmt::format("'{}' is not one of {}", text, format_choices()));
  }
  return std::string(text);
}
const std::string& format_help() {
  static const std::string help =
      fmt::format("recording format: {} (auto: from content and extension)", format_choices());
  return help;
}
constexpr std::array<std::pair<const char*, SampleType>, 4> kTypes{{{"int16", SampleType::int16},
                                                                    {"int32", SampleType::int32},
                                                                    {"float32", SampleType::float32},
                                                                    {"float64", SampleType::float64}}};
constexpr std::array<std::pair<const char*, ByteOrder>, 2> kOrders{{{"little", ByteOrder::little},
                                                                    {"big", ByteOrder::big}}};
constexpr std::array<std::pair<const char*, CorrelationPath>, 3> kPaths{{{"auto", CorrelationPath::automatic},
                                                                        {"intervals", CorrelationPath::intervals},
                                                                        {"fft", CorrelationPath::fft}}};

using R = ReaderOptions;
const OptionField<R> kReader[] = {
    {"format", "", format_help(),
     [](R& o, std::string_view t) { o.format = input_format(t); },
     [](const R& o) { return o.format; }},
    {"fs", "Hz", "sampling rate (needed for .dat, raw and CSV without a time column; must agree with a file's own)",
     [](R& o, std::string_view t) { o.fs = quantity(t, Dimension::frequency); },
     [](const R& o) { return o.fs > 0.0 ? format_quantity(o.fs, Dimension::frequency) : std::string("from the file"); }},
    {"override-fs", "", "let the stated sampling rate replace a different one recorded in the file",
     [](R& o, std::string_view t) { o.override_fs = on_off(t); },
     [](const R& o) { return std::string(switch_text(o.override_fs)); }, true},
    {"allow-truncated", "", "process what a WAV, W64 or RF64 file holds when its data is shorter than its header says",
     [](R& o, std::string_view t) { o.allow_truncated = on_off(t); },
     [](const R& o) { return std::string(switch_text(o.allow_truncated)); }, true},
    {"raw-type", "", "raw files: sample type int16 | int32 | float32 | float64",
     [](R& o, std::string_view t) { o.raw.sample_type = choice(t, kTypes); },
     [](const R& o) { return name_of(o.raw.sample_type, kTypes); }},
    {"raw-order", "", "raw files: byte order little | big",
     [](R& o, std::string_view t) { o.raw.byte_order = choice(t, kOrders); },
     [](const R& o) { return name_of(o.raw.byte_order, kOrders); }},
    {"raw-channels", "-", "raw files: channels per frame",
     [](R& o, std::string_view t) { o.raw.channels = static_cast<int>(whole(t, 1, 1024)); },
     [](const R& o) { return std::to_string(o.raw.channels); }},
    {"raw-header", "bytes", "raw files: header bytes to skip",
     [](R& o, std::string_view t) { o.raw.header_bytes = whole(t, 0, std::int64_t{1} << 50); },
     [](const R& o) { return std::to_string(o.raw.header_bytes); }},
    {"volts-per-count", "V",
     "volts per integer count (raw default 1; .dat 5/32768; audio: from a synthetic recording's sidecar, else "
     "normalised)",
     [](R& o, std::string_view t) { o.volts_per_count = o.raw.volts_per_count = quantity(t, Dimension::voltage); },
     [](const R& o) {
       return o.volts_per_count > 0.0 ? format_quantity(o.volts_per_count, Dimension::voltage) : std::string("the file's");
     }},
    {"tdms-channels", "", "TDMS: the channels to read, 'group/channel' or 'channel', comma-separated (default: every numeric channel)",
     [](R& o, std::string_view t) { o.tdms_channels = split_cells(t); },
     [](const R& o) { return cells_or(o.tdms_channels, "all"); }},
    {"dataset", "", "HDF5: the dataset(s) holding the channels, by path ('/run/volts'), comma-separated: one 2-D "
                    "dataset samples x channels or one 1-D dataset per channel (default: pdp-sim's 'signal', or the "
                    "only numeric dataset)",
     [](R& o, std::string_view t) { o.datasets = split_cells(t); },
     [](const R& o) { return cells_or(o.datasets, "found"); }},
    {"variable", "", "MATLAB .mat: the variable(s) holding the channels, comma-separated: one matrix samples x "
                     "channels or one vector per channel (default: the only numeric matrix with two or more columns)",
     [](R& o, std::string_view t) { o.variables = split_cells(t); },
     [](const R& o) { return cells_or(o.variables, "found"); }},
    {"csv-header", "", "CSV header row: auto | yes | no",
     [](R& o, std::string_view t) {
       if (t == "auto") o.csv.header.reset();
       else o.csv.header = on_off(t);
     },
     [](const R& o) { return o.csv.header ? std::string(*o.csv.header ? "yes" : "no") : std::string("auto"); }},
    {"time-column", "", "CSV time column: auto (by name) | none | its index from 0",
     [](R& o, std::string_view t) {
       if (t == "auto") o.csv.time_column = -2;
       else if (t == "none") o.csv.time_column = -1;
       else o.csv.time_column = static_cast<int>(whole(t, 0, 100000));
     },
     [](const R& o) {
       return o.csv.time_column == -2 ? std::string("auto")
                                      : (o.csv.time_column == -1 ? std::string("none") : std::to_string(o.csv.time_column));
     }},
};

using B = BinarisationOptions;
const OptionField<B> kBinarisation[] = {
    {"threshold-rule", "",
     "histogram | felder (Felder's program) | kramer (Kramer's toolbox, thres.m) | fixed (a voltage) | hysteresis (two "
     "thresholds)",
     [](B& o, std::string_view t) { o.rule = choice(t, values::threshold_rule); },
     [](const B& o) { return name_of(o.rule); }},
    {"threshold", "",
     "histogram/felder: fraction from air to water mode; fixed: a voltage (e.g. 2.5V); hysteresis: two fractions "
     "'low,high'",
     [](B& o, std::string_view t) {
       switch (o.rule) {
         case ThresholdRule::histogram:
         case ThresholdRule::felder:
         case ThresholdRule::kramer: o.theta = quantity(t, Dimension::dimensionless); break;
         case ThresholdRule::fixed: o.fixed_threshold = quantity(t, Dimension::voltage); break;
         case ThresholdRule::hysteresis: {
           const auto [lo, hi] = pair_of(t, "0.4,0.6");
           o.hysteresis_low = quantity(lo, Dimension::dimensionless);
           o.hysteresis_high = quantity(hi, Dimension::dimensionless);
           break;
         }
       }
     },
     [](const B& o) {
       switch (o.rule) {
         case ThresholdRule::fixed:
           return o.fixed_threshold ? format_quantity(*o.fixed_threshold, Dimension::voltage) : std::string("none");
         case ThresholdRule::hysteresis: return fmt::format("{:g},{:g}", o.hysteresis_low, o.hysteresis_high);
         default: return fmt::format("{:g}", o.theta);
       }
     }},
    {"threshold-trailing", "V", "fixed rule: the trailing tip's own threshold voltage (default: the leading tip's)",
     [](B& o, std::string_view t) { o.fixed_threshold_trailing = quantity(t, Dimension::voltage); },
     [](const B& o) {
       return o.fixed_threshold_trailing ? format_quantity(*o.fixed_threshold_trailing, Dimension::voltage)
                                         : std::string("the leading tip's");
     }},
    {"probe", "", "conductivity (air is the low level) | optical (air is the high level)",
     [](B& o, std::string_view t) { o.probe = choice(t, values::probe); },
     [](const B& o) { return name_of(o.probe); }},
    {"bin-width", "V", "voltage histogram bin width; 0 = 100 bins over the observed range",
     [](B& o, std::string_view t) { o.bin_width = quantity(t, Dimension::voltage); },
     [](const B& o) { return format_quantity(o.bin_width, Dimension::voltage); }},
};

using F = FsccOptions;
const OptionField<F> kFscc[] = {
    {"segments", "-", "FSCC segments: 1 = the full record; Felder's program used 15",
     [](F& o, std::string_view t) { o.segments = static_cast<int>(whole(t, 1, 1000)); },
     [](const F& o) { return std::to_string(o.segments); }},
    {"max-lag", "s", "FSCC lags searched: auto-correlation [0, max], cross-correlation [-max, max]",
     [](F& o, std::string_view t) { o.max_lag = quantity(t, Dimension::time); },
     [](const F& o) { return format_quantity(o.max_lag, Dimension::time); }},
    {"felder-lags", "", "Felder's program: auto lags 0..999, cross lags -199..800 samples, first peak within 1e-5",
     [](F& o, std::string_view t) { o.felder_lags = on_off(t); },
     [](const F& o) { return std::string(switch_text(o.felder_lags)); }, true},
    {"felder-scales", "",
     "Felder's program's time-scale rules: float32 lag times, first minimum within 1e-5, Txx and Txy one lag past "
     "the zero or to the minimum",
     [](F& o, std::string_view t) { o.felder_scales = on_off(t); },
     [](const F& o) { return std::string(switch_text(o.felder_scales)); }, true},
};

std::vector<double> quantity_list(std::string_view text, Dimension d, const char* example) {
  std::vector<double> out;
  for (const auto& cell : split_cells(text)) out.push_back(quantity(cell, d));
  if (out.empty()) throw std::invalid_argument(fmt::format("write the limits separated by commas, e.g. {}", example));
  return out;
}

std::string format_list(const std::vector<double>& values, Dimension d) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : ",") + format_quantity(v, d);
  return out;
}

using S = StructureOptions;
const OptionField<S> kStructure[] = {
    {"structure", "", "chord and voltage PDFs, clusters and inter-particle arrivals: on | off",
     [](S& o, std::string_view t) { o.enabled = on_off(t); },
     [](const S& o) { return std::string(switch_text(o.enabled)); }},
    {"felder-defects", "",
     "Felder's program's chord, cluster and arrival conventions and defects (to reproduce his printed numbers; "
     "docs/output.md lists them)",
     [](S& o, std::string_view t) { o.felder_defects = on_off(t); },
     [](const S& o) { return std::string(switch_text(o.felder_defects)); }, true},
    {"voltage-pdf-bin", "V", "bin width of the voltage PDF of each tip",
     [](S& o, std::string_view t) { o.voltage_bin = quantity(t, Dimension::voltage); },
     [](const S& o) { return format_quantity(o.voltage_bin, Dimension::voltage); }},
    {"chord-time-bin", "s", "bin width of the chord-time PDF",
     [](S& o, std::string_view t) { o.chord_time.bin_width = quantity(t, Dimension::time); },
     [](const S& o) { return format_quantity(o.chord_time.bin_width, Dimension::time); }},
    {"chord-time-max", "s", "upper end of the chord-time PDF (longer chords: the overflow bin)",
     [](S& o, std::string_view t) { o.chord_time.max = quantity(t, Dimension::time); },
     [](const S& o) { return format_quantity(o.chord_time.max, Dimension::time); }},
    {"chord-length-bin", "m", "bin width of the chord-length PDF",
     [](S& o, std::string_view t) { o.chord_length.bin_width = quantity(t, Dimension::length); },
     [](const S& o) { return format_quantity(o.chord_length.bin_width, Dimension::length); }},
    {"chord-length-max", "m", "upper end of the chord-length PDF (longer chords: the overflow bin)",
     [](S& o, std::string_view t) { o.chord_length.max = quantity(t, Dimension::length); },
     [](const S& o) { return format_quantity(o.chord_length.max, Dimension::length); }},
    {"cluster-median-fraction", "-", "median cluster criterion: fraction of the median separation (Chanson's 0.1)",
     [](S& o, std::string_view t) { o.clusters.median_fraction = quantity(t, Dimension::dimensionless); },
     [](const S& o) { return fmt::format("{:g}", o.clusters.median_fraction); }},
    {"cluster-constant-length", "m", "constant cluster criterion on chord lengths",
     [](S& o, std::string_view t) { o.clusters.constant_length = quantity(t, Dimension::length); },
     [](const S& o) { return format_quantity(o.clusters.constant_length, Dimension::length); }},
    {"cluster-constant-time", "s", "constant cluster criterion on chord times",
     [](S& o, std::string_view t) { o.clusters.constant_time = quantity(t, Dimension::time); },
     [](const S& o) { return format_quantity(o.clusters.constant_time, Dimension::time); }},
    {"arrival-bin", "s", "bin width of the inter-particle arrival-time histograms",
     [](S& o, std::string_view t) { o.arrivals.bin_width = quantity(t, Dimension::time); },
     [](const S& o) { return format_quantity(o.arrivals.bin_width, Dimension::time); }},
    {"arrival-bins", "-", "bins of the arrival-time histograms before the overflow bin",
     [](S& o, std::string_view t) { o.arrivals.bins = static_cast<int>(whole(t, 1, 1000000)); },
     [](const S& o) { return std::to_string(o.arrivals.bins); }},
    {"arrival-length-classes", "m", "upper limits of the particle size classes by chord length (a last class takes the rest)",
     [](S& o, std::string_view t) { o.arrivals.length_classes = quantity_list(t, Dimension::length, "1mm,3mm,6mm,10mm"); },
     [](const S& o) { return format_list(o.arrivals.length_classes, Dimension::length); }},
    {"arrival-time-classes", "s", "upper limits of the particle size classes by chord time (a last class takes the rest)",
     [](S& o, std::string_view t) { o.arrivals.time_classes = quantity_list(t, Dimension::time, "0.5ms,1.5ms,3ms,5ms"); },
     [](const S& o) { return format_list(o.arrivals.time_classes, Dimension::time); }},
};

// Felder's program (felder-program.md): his threshold rule, 15 segments of
// raw voltages, his lags and scale rules, his chord, cluster and arrival
// conventions; he had no AWCC.
constexpr PresetSetting kFelder[] = {
    {"threshold-rule", "felder"},  {"threshold", "0.5"},        {"segments", "15"},
    {"felder-lags", "on"},         {"felder-scales", "on"},      {"correlate", "raw"},
    {"method", "fscc"},            {"felder-defects", "on"},     {"voltage-pdf-bin", "0.1V"},
    {"chord-time-bin", "0.1ms"},   {"chord-time-max", "10ms"},   {"chord-length-bin", "0.5mm"},
    {"chord-length-max", "20mm"},  {"cluster-median-fraction", "0.1"}, {"cluster-constant-length", "1mm"},
    {"cluster-constant-time", "1ms"},  {"subsample", "none"},
};

// Kramer's AWCC toolbox: its threshold rule (thres.m), the raw voltages
// correlated, and the whole-sample peak of the published method (METHOD 4.3).
constexpr PresetSetting kKramer[] = {
    {"threshold-rule", "kramer"},
    {"correlate", "raw"},
    {"subsample", "none"},
};

using A = AwccOptions;
const OptionField<A> kAwcc[] = {
    {"np", "-", "AWCC particles (air chords of the leading tip) per window, 1-1000",
     [](A& o, std::string_view t) { o.np = static_cast<int>(whole(t, np_min, np_max)); },
     [](const A& o) { return std::to_string(o.np); }},
    {"filter-a", "-", "AWCC correlation filter threshold A: windows with R12max / (SPR^2 + 1) < A are rejected",
     [](A& o, std::string_view t) {
       o.filter_a = quantity(t, Dimension::dimensionless);
       if (!(o.filter_a >= 0.0 && o.filter_a <= 1.0)) throw std::invalid_argument(fmt::format("A = {} must lie in [0, 1]", t));
     },
     [](const A& o) { return fmt::format("{:g}", o.filter_a); }},
    {"roc", "", "AWCC robust outlier cutoff: on | off",
     [](A& o, std::string_view t) { o.roc = on_off(t); }, [](const A& o) { return std::string(switch_text(o.roc)); }},
    {"weighting", "", "AWCC moments: duration (window-duration weights, Buchhave 1979) | none",
     [](A& o, std::string_view t) { o.weighting = choice(t, values::weighting); },
     [](const A& o) { return name_of(o.weighting); }},
    {"correlate", "", "FSCC and AWCC correlate the binarised signals or the raw voltages (Felder's and Chanson's practice): binary | raw",
     [](A& o, std::string_view t) { o.signal = choice(t, values::signal); },
     [](const A& o) { return name_of(o.signal); }},
    {"velocity-range", "m/s", "AWCC lags searched from a velocity range 'min,max' (e.g. 0.5m/s,20m/s); default all lags",
     [](A& o, std::string_view t) {
       const auto [lo, hi] = pair_of(t, "0.5m/s,20m/s");
       o.velocity_min = quantity(lo, Dimension::velocity);
       o.velocity_max = quantity(hi, Dimension::velocity);
     },
     [](const A& o) {
       return o.velocity_min ? fmt::format("{},{}", format_quantity(*o.velocity_min, Dimension::velocity),
                                           format_quantity(*o.velocity_max, Dimension::velocity))
                             : std::string("all lags");
     }},
    {"subsample", "", "peak refinement of FSCC and AWCC below one sample: none | parabolic | gaussian | triangle | centroid",
     [](A& o, std::string_view t) { o.subsample = choice(t, values::subsample); },
     [](const A& o) { return name_of(o.subsample); }},
    {"windows-reported", "-", "AWCC quality: fewest accepted windows whose velocity and Tu are reported (insufficient below)",
     [](A& o, std::string_view t) { o.windows_reported = static_cast<int>(whole(t, 2, 1000000)); },
     [](const A& o) { return std::to_string(o.windows_reported); }},
    {"windows-ok", "-", "AWCC quality: fewest accepted windows of quality ok (low below)",
     [](A& o, std::string_view t) { o.windows_ok = static_cast<int>(whole(t, 2, 1000000)); },
     [](const A& o) { return std::to_string(o.windows_ok); }},
    {"yield-ok", "-", "AWCC quality: least data yield (accepted / total windows) of quality ok, e.g. 5%",
     [](A& o, std::string_view t) { o.yield_ok = quantity(t, Dimension::dimensionless); },
     [](const A& o) { return fmt::format("{:g}%", 100.0 * o.yield_ok); }},
    {"probe-correction", "",
     "bubble-probe interaction correction of every AWCC window (Hohermuth et al. 2021, Kramer's toolbox v1.3)",
     [](A& o, std::string_view t) { o.probe_correction.enabled = on_off(t); },
     [](const A& o) { return std::string(switch_text(o.probe_correction.enabled)); }, true},
    {"needle-diameter", "m", "probe correction: outer electrode (needle) diameter",
     [](A& o, std::string_view t) { o.probe_correction.needle_diameter = quantity(t, Dimension::length); },
     [](const A& o) { return format_quantity(o.probe_correction.needle_diameter, Dimension::length); }},
    {"probe-angle", "rad", "probe correction: angle between the probe axis and gravity (e.g. 45deg)",
     [](A& o, std::string_view t) { o.probe_correction.probe_angle = quantity(t, Dimension::angle); },
     [](const A& o) { return format_quantity(o.probe_correction.probe_angle, Dimension::angle); }},
    {"water-density", "kg/m3", "probe correction: density of the water",
     [](A& o, std::string_view t) { o.probe_correction.water_density = quantity(t, Dimension::density); },
     [](const A& o) { return format_quantity(o.probe_correction.water_density, Dimension::density); }},
    {"water-viscosity", "m2/s", "probe correction: kinematic viscosity of the water",
     [](A& o, std::string_view t) { o.probe_correction.water_viscosity = quantity(t, Dimension::kinematic_viscosity); },
     [](const A& o) { return format_quantity(o.probe_correction.water_viscosity, Dimension::kinematic_viscosity); }},
    {"air-density", "kg/m3", "probe correction: density of the air",
     [](A& o, std::string_view t) { o.probe_correction.air_density = quantity(t, Dimension::density); },
     [](const A& o) { return format_quantity(o.probe_correction.air_density, Dimension::density); }},
    {"surface-tension", "N/m", "probe correction: air-water surface tension",
     [](A& o, std::string_view t) { o.probe_correction.surface_tension = quantity(t, Dimension::surface_tension); },
     [](const A& o) { return format_quantity(o.probe_correction.surface_tension, Dimension::surface_tension); }},
    {"contact-factor", "-", "probe correction: contact (surface tension) force factor b",
     [](A& o, std::string_view t) { o.probe_correction.contact_factor = quantity(t, Dimension::dimensionless); },
     [](const A& o) { return fmt::format("{:g}", o.probe_correction.contact_factor); }},
    {"virtual-mass", "-", "probe correction: virtual-mass coefficient c_VM",
     [](A& o, std::string_view t) { o.probe_correction.virtual_mass = quantity(t, Dimension::dimensionless); },
     [](const A& o) { return fmt::format("{:g}", o.probe_correction.virtual_mass); }},
    {"impact-pressure", "-", "probe correction: impact pressure coefficient C_p",
     [](A& o, std::string_view t) { o.probe_correction.impact_pressure = quantity(t, Dimension::dimensionless); },
     [](const A& o) { return fmt::format("{:g}", o.probe_correction.impact_pressure); }},
    {"path", "", "AWCC correlation of binary signals: auto (intervals) | intervals | fft (same result, other cost)",
     [](A& o, std::string_view t) { o.path = choice(t, kPaths); },
     [](const A& o) { return name_of(o.path, kPaths); }},
};

// An optional quantity of a setting: "none" or a value with its unit.
std::optional<double> quantity_or_none(std::string_view t, Dimension d) {
  if (t == "none") return std::nullopt;
  return quantity(t, d);
}
std::string text_or_none(const std::optional<double>& v, Dimension d) {
  return v ? format_quantity(*v, d) : std::string("none");
}

using PF = ProfileFlowOptions;
const OptionField<PF> kFlow[] = {
    {"discharge", "m2/s",
     "profile: the discharge per unit width the lab set (e.g. 0.2m2/s, 150l/s/m), for the continuity error "
     "(q_w - q) / q; none: no check",
     [](PF& o, std::string_view t) { o.discharge = quantity_or_none(t, Dimension::discharge_per_width); },
     [](const PF& o) { return text_or_none(o.discharge, Dimension::discharge_per_width); }},
    {"invert", "",
     "profile: the void fraction from the invert to the first position, which no probe reaches: held (the first "
     "reading) | zero | left-out",
     [](PF& o, std::string_view t) { o.invert = choice(t, invert_rules); },
     [](const PF& o) { return name_of(o.invert); }},
    {"depth-levels", "-", "profile: void fractions of the characteristic depths reported besides Y90, e.g. 0.5,0.95",
     [](PF& o, std::string_view t) {
       o.levels.clear();
       if (t == "none") return;
       for (const auto& cell : split_cells(t)) o.levels.push_back(quantity(cell, Dimension::dimensionless));
     },
     [](const PF& o) {
       if (o.levels.empty()) return std::string("none");
       std::string out;
       for (double l : o.levels) out += fmt::format("{}{:g}", out.empty() ? "" : ",", l);
       return out;
     }},
    {"chute-angle", "rad",
     "profile: the chute's angle to the horizontal (e.g. 50deg), for the residual head H_res = d cos(theta) + "
     "q_w^2 / (2 g d^2); none: no residual head",
     [](PF& o, std::string_view t) { o.chute_angle = quantity_or_none(t, Dimension::angle); },
     [](const PF& o) { return text_or_none(o.chute_angle, Dimension::angle); }},
    {"flow-draws", "-", "profile: Monte Carlo draws of the profile quantities' 95 % intervals",
     [](PF& o, std::string_view t) { o.draws = static_cast<int>(whole(t, 100, 10000000)); },
     [](const PF& o) { return std::to_string(o.draws); }},
    {"flow-seed", "-", "profile: the Monte Carlo seed (the same seed, the same intervals)",
     [](PF& o, std::string_view t) { o.seed = static_cast<std::uint64_t>(whole(t, 0, 9007199254740991LL)); },
     [](const PF& o) { return std::to_string(o.seed); }},
};

using M = MultiTipOptions;
const OptionField<M> kMultiTip[] = {
    {"velocity-algorithm", "",
     "multi-tip velocity per bubble: shen-nakamura (Shen & Nakamura 2014: also each bubble's diameter, normals and "
     "interfacial area) | tian (Tian et al. 2015: the same velocity, no sizes)",
     [](M& o, std::string_view t) { o.algorithm = choice(t, velocity_algorithms); },
     [](const M& o) { return name_of(o.algorithm); }},
    {"conditioning-min", "-",
     "multi-tip: least |det A_0| (0-1) of the direction cosines of three trailing tips; a combination below it is "
     "skipped (timing errors amplified up to 1.5 / |det A_0| times)",
     [](M& o, std::string_view t) { o.conditioning_min = quantity(t, Dimension::dimensionless); },
     [](const M& o) { return fmt::format("{:g}", o.conditioning_min); }},
    {"vector-roc", "", "multi-tip: robust outlier cutoff of the per-bubble velocity vectors, per component: on | off",
     [](M& o, std::string_view t) { o.roc = on_off(t); },
     [](const M& o) { return std::string(switch_text(o.roc)); }},
    {"vectors-reported", "-", "multi-tip: fewest accepted bubbles whose mean vector, stresses and Tu are reported",
     [](M& o, std::string_view t) { o.vectors_reported = static_cast<int>(whole(t, 2, 1000000000)); },
     [](const M& o) { return std::to_string(o.vectors_reported); }},
};

using E = EventOptions;
const OptionField<E> kEvents[] = {
    {"interface-times", "",
     "event detection's and the multi-tip pairing's interface times: midpoint (half way between the samples that "
     "straddle the edge: lags of whole samples) | crossing (where the voltage crosses the threshold, interpolated "
     "between the two samples: lags below a sample; one more pass over the file; a binary signal gives the "
     "midpoint; refused where neither event detection nor a multi-tip probe runs)",
     [](E& o, std::string_view t) { o.interface_times = choice(t, values::interface_timing); },
     [](const E& o) { return name_of(o.interface_times); }},
    {"pairing", "",
     "event detection's interface pairing: kramer (Kramer et al. 2020: centre lag and chord-time disparity) | shen "
     "(Shen et al. 2005: lags within |S| / (f V_gas), V_gas from FSCC or AWCC)",
     [](E& o, std::string_view t) { o.pairing = choice(t, values::pairing); },
     [](const E& o) { return name_of(o.pairing); }},
    {"chord-disparity-max", "-",
     "Kramer pairing: largest relative chord-time disparity |dt_0 - dt_k| / dt_0 of a pair (lower refuses more "
     "off-centre true pairs, higher accepts more wrong ones)",
     [](E& o, std::string_view t) { o.disparity_max = quantity(t, Dimension::dimensionless); },
     [](const E& o) { return fmt::format("{:g}", o.disparity_max); }},
    {"shen-lag-factor", "-",
     "Shen pairing: f in the lag limit |S| / (f V_gas); 0.3 pairs bubbles down to 30 % of the mean velocity",
     [](E& o, std::string_view t) { o.shen_lag_factor = quantity(t, Dimension::dimensionless); },
     [](const E& o) { return fmt::format("{:g}", o.shen_lag_factor); }},
    {"probe-speed-min", "-",
     "multi-tip pairing: slowest bubble paired, as a fraction of the first velocity (FSCC's); sets the long end of "
     "each trailing tip's lag window",
     [](E& o, std::string_view t) { o.probe_speed_min = quantity(t, Dimension::dimensionless); },
     [](const E& o) { return fmt::format("{:g}", o.probe_speed_min); }},
    {"probe-speed-max", "-",
     "multi-tip pairing: fastest bubble paired, as a multiple of the first velocity; sets the short end of each "
     "lag window",
     [](E& o, std::string_view t) { o.probe_speed_max = quantity(t, Dimension::dimensionless); },
     [](const E& o) { return fmt::format("{:g}", o.probe_speed_max); }},
    {"probe-angle-max", "deg",
     "multi-tip pairing: largest angle between a bubble's velocity and the streamwise axis (raise it for strongly "
     "3-D flows)",
     [](E& o, std::string_view t) { o.probe_angle_max = quantity(t, Dimension::dimensionless); },
     [](const E& o) { return fmt::format("{:g}", o.probe_angle_max); }},
    {"probe-diameter-mismatch", "-",
     "multi-tip pairing: largest |D_front - D_rear| / D of a bubble's Shen & Nakamura diameters (0 for a sphere "
     "paired right); raise it for bubbles far from spheres",
     [](E& o, std::string_view t) { o.probe_diameter_mismatch = quantity(t, Dimension::dimensionless); },
     [](const E& o) { return fmt::format("{:g}", o.probe_diameter_mismatch); }},
    {"bubbles-reported", "-",
     "event detection quality: fewest paired bubbles whose velocity and Tu are reported (insufficient below)",
     [](E& o, std::string_view t) { o.bubbles_reported = static_cast<int>(whole(t, 2, 1000000000)); },
     [](const E& o) { return std::to_string(o.bubbles_reported); }},
    {"bubbles-ok", "-", "event detection quality: fewest paired bubbles of quality ok (low below)",
     [](E& o, std::string_view t) { o.bubbles_ok = static_cast<int>(whole(t, 2, 1000000000)); },
     [](const E& o) { return std::to_string(o.bubbles_ok); }},
    {"pairing-yield-ok", "-",
     "event detection quality: least pairing yield (paired / complete leading bubbles) of quality ok, e.g. 5%",
     [](E& o, std::string_view t) { o.pairing_yield_ok = quantity(t, Dimension::dimensionless); },
     [](const E& o) { return fmt::format("{:g}%", 100.0 * o.pairing_yield_ok); }},
};

using P = ProcessOptions;
constexpr std::array<std::pair<const char*, int>, 4> kMethods{{{"both", 3}, {"awcc", 2}, {"fscc", 1}, {"none", 0}}};

// The method option: names joined by '+'. A correlation choice (kMethods),
// auto (multi-tip for a probe of four or more tips), events, multi-tip;
// without a correlation choice, both (bubble-by-bubble methods are checked
// against FSCC and AWCC). Every combination of the fields is written so that
// it reads back the same: auto, both, events, auto+events, fscc+auto, ...
void set_method(P& o, std::string_view text) {
  o.events = false;
  o.multi_tip = MultiTipChoice::off;
  std::optional<int> correlations;
  for (const auto& cell : split_cells(text, '+')) {
    if (cell == "auto") {
      o.multi_tip = MultiTipChoice::automatic;
    } else if (cell == "events") {
      o.events = true;
    } else if (cell == "multi-tip") {
      o.multi_tip = MultiTipChoice::on;
    } else {
      if (correlations) throw std::invalid_argument(fmt::format("'{}' names two correlation choices", text));
      correlations = choice(cell, kMethods);
    }
  }
  const int m = correlations.value_or(3);
  o.fscc = (m & 1) != 0;
  o.awcc = (m & 2) != 0;
}

std::string method_text(const P& o) {
  std::vector<std::string> names;
  const std::string base = name_of((o.fscc ? 1 : 0) | (o.awcc ? 2 : 0), kMethods);
  if (o.multi_tip == MultiTipChoice::automatic) names.emplace_back("auto");
  if (o.multi_tip == MultiTipChoice::on) names.emplace_back("multi-tip");
  if (o.events) names.emplace_back("events");
  if (base != "both" || names.empty()) names.insert(names.begin(), base);
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : "+") + n;
  return out;
}

// The probe's tips first: probe_option_fields() is their span, and a later
// option's parse may read them.
constexpr std::size_t kProbeFields = 3;
const OptionField<P> kProcess[] = {
    {"tips", "m",
     "the probe's tip positions x,y,z (x streamwise), a unit on each value, tips separated by ';' (e.g. "
     "'0mm,0mm,0mm;5mm,0mm,0mm;5mm,1.5mm,0mm;5mm,0mm,1.5mm'): instead of dx and dy",
     [](P& o, std::string_view t) {
       o.probe.positions = parse_points(t);
       if (const auto why = tips_problem(o.probe.positions); !why.empty()) throw std::invalid_argument(why);
     },
     [](const P& o) { return o.probe.declared() ? format_points(o.probe.positions) : std::string("dx and dy"); }},
    {"leading-tip", "-", "with tips: the leading tip, by its place in the list (from 0)",
     [](P& o, std::string_view t) { o.probe.leading = static_cast<int>(whole(t, 0, 1023)); },
     [](const P& o) { return std::to_string(o.probe.leading); }},
    {"tip-channels", "-", "with tips: each tip's recording channel (from 0), in the order of the tips, e.g. 0,1,3,2",
     [](P& o, std::string_view t) {
       o.probe.channels.clear();
       for (const auto& cell : split_cells(t)) o.probe.channels.push_back(static_cast<int>(whole(cell, 0, 1023)));
       if (const auto why = channels_problem(o.probe.channels); !why.empty()) throw std::invalid_argument(why);
     },
     [](const P& o) { return o.probe.channels.empty() ? std::string("tip k on channel k") : cells_of(o.probe.channels); }},
    {"dx", "m", "streamwise tip separation (e.g. 7.15mm); 0 = no velocity",
     [](P& o, std::string_view t) { o.dx = quantity(t, Dimension::length); },
     [](const P& o) { return format_quantity(o.dx, Dimension::length); }},
    {"dy", "m", "lateral tip separation (reported; a feature of the bias correction)",
     [](P& o, std::string_view t) { o.dy = quantity(t, Dimension::length); },
     [](const P& o) { return format_quantity(o.dy, Dimension::length); }},
    {"leading-channel", "-", "channel of the leading tip (from 0)",
     [](P& o, std::string_view t) { o.leading_channel = static_cast<int>(whole(t, 0, 1023)); },
     [](const P& o) { return std::to_string(o.leading_channel); }},
    {"trailing-channel", "-", "channel of the trailing tip (from 0)",
     [](P& o, std::string_view t) { o.trailing_channel = static_cast<int>(whole(t, 0, 1023)); },
     [](const P& o) { return std::to_string(o.trailing_channel); }},
    {"method", "",
     "velocity methods: auto (both; multi-tip for a probe of four or more tips) | both (FSCC and AWCC) | awcc | fscc | "
     "none (phase statistics only) | events (event detection on the tip pair, a velocity per bubble, checked against "
     "FSCC and AWCC) | multi-tip (3-D velocity, size and interfacial area bubble by bubble, FSCC and AWCC on every tip "
     "pair); fscc+events, awcc+multi-tip, ... run fewer correlations",
     set_method, method_text},
    {"histogram-bins", "-", "bins of the chord-time histograms",
     [](P& o, std::string_view t) { o.histogram_bins = static_cast<int>(whole(t, 1, 100000)); },
     [](const P& o) { return std::to_string(o.histogram_bins); }},
    {"velocity-spectrum", "", "spectrum and integral time scale of AWCC's velocity series: on | off",
     [](P& o, std::string_view t) { o.velocity_spectrum = on_off(t); },
     [](const P& o) { return std::string(switch_text(o.velocity_spectrum)); }},
    {"sizes", "",
     "the number distribution of bubble (droplet) diameters inverted from the leading tip's chord lengths, each at "
     "its bubble's, its AWCC window's or the record's velocity (METHOD 12): on | off",
     [](P& o, std::string_view t) { o.sizes = on_off(t); },
     [](const P& o) { return std::string(switch_text(o.sizes)); }},
    {"size-chords-min", "-",
     "sizes: fewest chords inverted into a distribution (below, d32 = 1.5 x mean chord only); at 200 the number "
     "median spreads by 6-13 % over draws, at 50 by 16-34 %",
     [](P& o, std::string_view t) { o.size_options.inversion.chords_min = static_cast<int>(whole(t, 10, 1000000000)); },
     [](const P& o) { return std::to_string(o.size_options.inversion.chords_min); }},
    {"size-penalty", "-",
     "sizes: weight of the penalty on the third derivative of ln(pierced density) in ln D; 0.01-0.1 leave spikes at "
     "small D, 1 is the weakest stable one",
     [](P& o, std::string_view t) { o.size_options.inversion.penalty = quantity(t, Dimension::dimensionless); },
     [](const P& o) { return fmt::format("{:g}", o.size_options.inversion.penalty); }},
    {"size-bin-width", "-", "sizes: width of a diameter bin in ln D (0.05 = 5 % steps)",
     [](P& o, std::string_view t) { o.size_options.inversion.bin_width = quantity(t, Dimension::dimensionless); },
     [](const P& o) { return fmt::format("{:g}", o.size_options.inversion.bin_width); }},
    {"size-samples-min", "-",
     "sizes: least number median diameter in samples (its chord time's); below, the sampling grid shapes the "
     "distribution and none is given (at 2 samples the median comes out 15 % low)",
     [](P& o, std::string_view t) { o.size_options.samples_min = quantity(t, Dimension::dimensionless); },
     [](const P& o) { return fmt::format("{:g}", o.size_options.samples_min); }},
    {"spectrum-segment", "-", "Welch segment length of the velocity spectrum, in resampled points",
     [](P& o, std::string_view t) { o.spectrum.segment_length = static_cast<int>(whole(t, 8, 1 << 24)); },
     [](const P& o) { return std::to_string(o.spectrum.segment_length); }},
    {"allow-unusual", "", "accept dx outside 0.1-100 mm, fs outside 1 kHz-100 MHz, velocities outside 0.01-200 m/s",
     [](P& o, std::string_view t) { o.allow_unusual = on_off(t); },
     [](const P& o) { return std::string(switch_text(o.allow_unusual)); }, true},
    {"allow-bad-signal", "",
     "process a tip whose voltage fails the signal check (noise, a dead or clipped channel, inverted polarity), the "
     "failure in every output",
     [](P& o, std::string_view t) { o.signal_check.allow_bad_signal = on_off(t); },
     [](const P& o) { return std::string(switch_text(o.signal_check.allow_bad_signal)); }, true},
};

}  // namespace

std::span<const OptionField<ReaderOptions>> reader_option_fields() { return kReader; }
std::span<const OptionField<BinarisationOptions>> binarisation_option_fields() { return kBinarisation; }
std::span<const OptionField<FsccOptions>> fscc_option_fields() { return kFscc; }
std::span<const OptionField<AwccOptions>> awcc_option_fields() { return kAwcc; }
std::span<const OptionField<ProcessOptions>> process_option_fields() { return kProcess; }
std::span<const OptionField<ProcessOptions>> probe_option_fields() {
  return std::span<const OptionField<ProcessOptions>>(kProcess).first(kProbeFields);
}
std::span<const OptionField<StructureOptions>> structure_option_fields() { return kStructure; }
std::span<const OptionField<MultiTipOptions>> multi_tip_option_fields() { return kMultiTip; }
std::span<const OptionField<EventOptions>> event_option_fields() { return kEvents; }
std::span<const OptionField<ProfileFlowOptions>> profile_flow_option_fields() { return kFlow; }


std::span<const PresetSetting> preset_settings(std::string_view name) {
  if (name == "felder") return kFelder;
  if (name == "kramer") return kKramer;
  throw OptionError(fmt::format("'{}' is not a preset; the presets are: felder, kramer", name), "preset");
}

namespace {

// The settings as applied: the preset's values (origin "preset NAME") before
// the user's, so that a setting the user gives wins (the last given wins).
std::vector<OptionSetting> behind_preset(std::span<const OptionSetting> settings) {
  const OptionSetting* preset = nullptr;
  for (const auto& s : settings)
    if (s.name == "preset") preset = &s;
  std::vector<OptionSetting> out;
  if (preset) {
    std::span<const PresetSetting> values;
    try {
      values = preset_settings(preset->value);
    } catch (const std::invalid_argument& e) {
      throw setting_error(*preset, e.what());
    }
    for (const auto& v : values) out.push_back({std::string(v.name), std::string(v.value), "preset " + preset->value});
  }
  for (const auto& s : settings)
    if (s.name != "preset") out.push_back(s);
  return out;
}

void refuse_unknown(std::span<const OptionSetting> settings, const std::vector<bool>& used, std::string_view of) {
  for (std::size_t i = 0; i < settings.size(); ++i) {
    if (!used[i]) {
      throw OptionError(fmt::format("'{}' is not the declared name of an option of {} (awcc/options.hpp lists them)",
                                    settings[i].name, of),
                        settings[i].name);
    }
  }
}

void apply_methods(std::span<const OptionSetting> settings, std::vector<bool>& used, AwccOptions& awcc,
                   FsccOptions& fscc) {
  apply_settings(fscc_option_fields(), settings, fscc, used);
  apply_settings(awcc_option_fields(), settings, awcc, used);
  fscc.subsample = awcc.subsample;  // the one owner of this rule (options.hpp)
}

}  // namespace

void method_options(std::span<const OptionSetting> settings, AwccOptions& awcc, FsccOptions& fscc) {
  std::vector<bool> used(settings.size(), false);
  apply_methods(settings, used, awcc, fscc);
  refuse_unknown(settings, used, "AWCC or FSCC");
  awcc.validate().throw_if_failed();
  fscc.validate().throw_if_failed();
}

ProcessOptions process_options(std::span<const OptionSetting> given) {
  const auto settings = behind_preset(given);
  std::vector<bool> used(settings.size(), false);
  ProcessOptions p;
  apply_settings(process_option_fields(), std::span<const OptionSetting>(settings), p, used);
  apply_settings(reader_option_fields(), std::span<const OptionSetting>(settings), p.reader, used);
  apply_settings(binarisation_option_fields(), std::span<const OptionSetting>(settings), p.binarisation, used);
  apply_methods(settings, used, p.awcc_options, p.fscc_options);
  apply_settings(structure_option_fields(), std::span<const OptionSetting>(settings), p.structure, used);
  apply_settings(event_option_fields(), std::span<const OptionSetting>(settings), p.event_options, used);
  apply_settings(multi_tip_option_fields(), std::span<const OptionSetting>(settings), p.multi_tip_options, used);
  refuse_unknown(settings, used, "a processing run");
  // An implausible value is named before a combination it may cause.
  if (!p.allow_unusual) p.implausible().throw_if_failed();
  p.validate().throw_if_failed();
  return p;
}

ProfileFlowOptions profile_flow_options(std::span<const OptionSetting> settings) {
  std::vector<bool> used(settings.size(), false);
  ProfileFlowOptions out;
  apply_settings(profile_flow_option_fields(), settings, out, used);
  refuse_unknown(settings, used, "a profile's flow quantities");
  out.validate().throw_if_failed();
  return out;
}

}  // namespace awcc
