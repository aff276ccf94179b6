#pragma once
// Reading back what awcc/serialise.hpp writes. The process JSON's keys that
// other parts read and the profile CSV's columns are named here once; the
// writer writes by these names and every reader (libcorrection's rows, the
// Python module) reads by them. Each enum of a result has one parser, the
// inverse of its to_string: a text pdp does not write is an InputError
// naming the file, the row and the value, never a default.

#include <string>
#include <string_view>
#include <vector>

#include "awcc/awcc.hpp"
#include "awcc/event_detection.hpp"
#include "awcc/binarisation.hpp"
#include "awcc/flags.hpp"
#include "awcc/fscc.hpp"
#include "awcc/phase_statistics.hpp"
#include "awcc/process.hpp"

namespace awcc {

/// The values of the enums that are both options and written results, in the
/// order pdp lists them. Each value's text is its to_string: the option
/// parser and formatter (options.cpp), the writer and the parsers below all
/// spell a value by it, so a renamed value is read as it is written.
namespace values {
inline constexpr Weighting weighting[] = {Weighting::duration, Weighting::none};
inline constexpr CorrelationSignal signal[] = {CorrelationSignal::binary, CorrelationSignal::raw};
inline constexpr Subsample subsample[] = {Subsample::none, Subsample::parabolic, Subsample::gaussian,
                                          Subsample::triangle, Subsample::centroid};
inline constexpr ThresholdRule threshold_rule[] = {ThresholdRule::histogram, ThresholdRule::felder,
                                                   ThresholdRule::kramer, ThresholdRule::fixed,
                                                   ThresholdRule::hysteresis};
inline constexpr ProbeType probe[] = {ProbeType::conductivity, ProbeType::optical};
inline constexpr Pairing pairing[] = {Pairing::kramer, Pairing::shen};
inline constexpr InterfaceTiming interface_timing[] = {InterfaceTiming::midpoint, InterfaceTiming::crossing};
}  // namespace values

/// A switch as pdp writes it (a profile CSV's "on"/"off", an option's value).
constexpr std::string_view switch_text(bool on) { return on ? "on" : "off"; }

/// Where a text was read: the file, the row (a JSON pointer such as
/// "/profile/3/awcc", or "line 7" of a CSV) and the key or column.
struct WrittenAt {
  std::string_view file;
  std::string_view row;
  std::string_view field;
};

PhaseStatus parse_phase_status(std::string_view text, const WrittenAt& at);
FsccStatus parse_fscc_status(std::string_view text, const WrittenAt& at);
AwccStatus parse_awcc_status(std::string_view text, const WrittenAt& at);
AwccQuality parse_awcc_quality(std::string_view text, const WrittenAt& at);
Weighting parse_weighting(std::string_view text, const WrittenAt& at);
CorrelationSignal parse_correlation_signal(std::string_view text, const WrittenAt& at);
Subsample parse_subsample(std::string_view text, const WrittenAt& at);
WindowFate parse_window_fate(std::string_view text, const WrittenAt& at);
VelocitySource parse_velocity_source(std::string_view text, const WrittenAt& at);
/// One flag code of a row's "flags" (a JSON list's entry, or one of a CSV
/// cell's codes joined by "; ").
Flag parse_flag(std::string_view text, const WrittenAt& at);
/// A profile CSV's flags cell: its codes in order (none for an empty cell).
std::vector<Flag> parse_flags_cell(std::string_view cell, const WrittenAt& at);
/// A switch of the profile CSV ("on"/"off", as profile_csv_row writes a JSON
/// true/false).
bool parse_switch(std::string_view text, const WrittenAt& at);

/// The texts a profile CSV column may hold, by its name: an enum's values
/// (by its to_string), a switch's on/off, or the flag codes whose list the
/// flags column joins; empty for a number or free text.
/// The Python module hands them to the report (pdp.profile_columns()).
std::vector<std::string_view> written_values(std::string_view column);

/// The keys of the process JSON that are read back (docs/output.md). A
/// recording's object:
namespace process_key {
inline constexpr std::string_view profile = "profile";  ///< a profile's list of recordings' objects
inline constexpr std::string_view flow = "flow";        ///< a profile's flow quantities (awcc/profile_flow.hpp)
/// In a profile's flow: the air-concentration models' fits (the Python module evaluates their curves).
inline constexpr std::string_view smooth_chute = "smooth_chute";
inline constexpr std::string_view stepped_chute = "stepped_chute";
inline constexpr std::string_view file = "file";        ///< the recording's path
inline constexpr std::string_view position = "position";  ///< a profile entry's position, m (null: none given)
inline constexpr std::string_view chord_velocity_source = "chord_velocity_source";  ///< ProcessResult::velocity_source()
inline constexpr std::string_view tips = "tips";
inline constexpr std::string_view fscc = "fscc";
inline constexpr std::string_view awcc = "awcc";
inline constexpr std::string_view events = "events";        ///< event detection on the tip pair
inline constexpr std::string_view multi_tip = "multi_tip";  ///< a multi-tip probe bubble by bubble
inline constexpr std::string_view sizes = "sizes";          ///< the size distribution (awcc/position_sizes.hpp)
inline constexpr std::string_view interfacial_area = "interfacial_area";
inline constexpr std::string_view fs = "fs";
inline constexpr std::string_view samples = "samples";
inline constexpr std::string_view duration = "duration";
inline constexpr std::string_view dx = "dx";
inline constexpr std::string_view dy = "dy";
/// The row's warnings (texts) and their flags (codes), one each, in order (awcc/flags.hpp).
inline constexpr std::string_view warnings = "warnings";
inline constexpr std::string_view flags = "flags";
// In a tip's, FSCC's or AWCC's object:
inline constexpr std::string_view status = "status";
inline constexpr std::string_view reason = "reason";
inline constexpr std::string_view void_fraction = "void_fraction";
inline constexpr std::string_view void_fraction_ci95 = "void_fraction_ci95";  ///< [lower, upper]
inline constexpr std::string_view bubble_count_rate = "bubble_count_rate";
inline constexpr std::string_view bubble_count_rate_ci95 = "bubble_count_rate_ci95";
inline constexpr std::string_view velocity = "velocity";
inline constexpr std::string_view velocity_ci95 = "velocity_ci95";  ///< FSCC's or AWCC's; null when none
inline constexpr std::string_view r12_max = "r12_max";
/// FSCC's: Chanson's Tu from the half-widths; null where tau05 < T05 or a
/// half-width is not found (libcorrection's "+chanson" feature reads it).
inline constexpr std::string_view turbulence_intensity_chanson = "turbulence_intensity_chanson";
inline constexpr std::string_view turbulence_intensity = "turbulence_intensity";
/// AWCC's: false when every accepted window peaks at one lag (Tu then null);
/// absent from a JSON of an earlier pdp (measured).
inline constexpr std::string_view turbulence_measured = "turbulence_measured";
inline constexpr std::string_view quality_reason = "quality_reason";  ///< AWCC's: why the quality is not ok
/// AWCC's accepted windows at the least and the greatest lag of the velocity range.
inline constexpr std::string_view windows_at_least_lag = "windows_at_least_lag";
inline constexpr std::string_view windows_at_greatest_lag = "windows_at_greatest_lag";
inline constexpr std::string_view windows_accepted = "windows_accepted";
inline constexpr std::string_view windows_total = "windows_total";
inline constexpr std::string_view time_scale_ratio = "time_scale_ratio";  ///< AWCC's, capped (AwccResult)
inline constexpr std::string_view np = "np";
inline constexpr std::string_view probe_corrected = "probe_corrected";
inline constexpr std::string_view options = "options";
// In AWCC's options (to_json(AwccOptions)):
inline constexpr std::string_view filter_a = "filter_a";
inline constexpr std::string_view roc = "roc";
inline constexpr std::string_view weighting = "weighting";
/// Also a tip's object's key of its signal check (awcc/signal_check.hpp).
inline constexpr std::string_view signal = "signal";
inline constexpr std::string_view subsample = "subsample";
// In sizes (docs/output.md; the Python module's `sizes` reads them):
inline constexpr std::string_view bins = "bins";
inline constexpr std::string_view bin_edges = "edges";
inline constexpr std::string_view bin_diameters = "diameters";
inline constexpr std::string_view bin_density = "density";
inline constexpr std::string_view bin_cumulative = "cumulative";
inline constexpr std::string_view median = "median";
inline constexpr std::string_view d10 = "d10";
inline constexpr std::string_view d20 = "d20";
inline constexpr std::string_view d30 = "d30";
inline constexpr std::string_view d32 = "d32";
inline constexpr std::string_view d32_chords = "d32_chords";
inline constexpr std::string_view d32_flux = "d32_flux";
inline constexpr std::string_view dispersed_phase = "dispersed_phase";
inline constexpr std::string_view chords_used = "chords_used";
/// Retired by issue 28: a JSON written before the "status" keys existed says
/// only whether FSCC or AWCC gave a value (docs/output.md).
inline constexpr std::string_view retired_defined = "defined";
}  // namespace process_key

/// The profile CSV's columns that are read back; profile_csv_columns
/// declares them (with units and meanings) by these names.
namespace profile_column {
inline constexpr std::string_view file = "file";
inline constexpr std::string_view position = "position";
inline constexpr std::string_view void_fraction = "void_fraction";
inline constexpr std::string_view bubble_count_rate = "bubble_count_rate";
inline constexpr std::string_view void_fraction_ci95_lower = "void_fraction_ci95_lower";
inline constexpr std::string_view void_fraction_ci95_upper = "void_fraction_ci95_upper";
inline constexpr std::string_view bubble_count_rate_ci95_lower = "bubble_count_rate_ci95_lower";
inline constexpr std::string_view bubble_count_rate_ci95_upper = "bubble_count_rate_ci95_upper";
inline constexpr std::string_view fscc_velocity_ci95_lower = "fscc_velocity_ci95_lower";
inline constexpr std::string_view fscc_velocity_ci95_upper = "fscc_velocity_ci95_upper";
inline constexpr std::string_view awcc_velocity_ci95_lower = "awcc_velocity_ci95_lower";
inline constexpr std::string_view awcc_velocity_ci95_upper = "awcc_velocity_ci95_upper";
inline constexpr std::string_view fscc_velocity = "fscc_velocity";
inline constexpr std::string_view events_velocity = "events_velocity";
inline constexpr std::string_view events_quality = "events_quality";
inline constexpr std::string_view multi_tip_status = "multi_tip_status";
inline constexpr std::string_view multi_tip_quality = "multi_tip_quality";
inline constexpr std::string_view fscc_r12_max = "fscc_r12_max";
inline constexpr std::string_view fscc_turbulence_intensity_chanson = "fscc_turbulence_intensity_chanson";
inline constexpr std::string_view awcc_velocity = "awcc_velocity";
inline constexpr std::string_view awcc_turbulence_intensity = "awcc_turbulence_intensity";
inline constexpr std::string_view awcc_windows_accepted = "awcc_windows_accepted";
inline constexpr std::string_view awcc_windows_total = "awcc_windows_total";
inline constexpr std::string_view fscc_status = "fscc_status";
inline constexpr std::string_view awcc_status = "awcc_status";
inline constexpr std::string_view awcc_reason = "awcc_reason";
inline constexpr std::string_view dx = "dx";
inline constexpr std::string_view dy = "dy";
inline constexpr std::string_view np = "np";
inline constexpr std::string_view awcc_filter_a = "awcc_filter_a";
inline constexpr std::string_view awcc_roc = "awcc_roc";
inline constexpr std::string_view awcc_weighting = "awcc_weighting";
inline constexpr std::string_view awcc_signal = "awcc_signal";
inline constexpr std::string_view awcc_subsample = "awcc_subsample";
inline constexpr std::string_view fs = "fs";
inline constexpr std::string_view duration = "duration";
inline constexpr std::string_view awcc_quality = "awcc_quality";
inline constexpr std::string_view chord_velocity_source = "chord_velocity_source";
inline constexpr std::string_view awcc_probe_corrected = "awcc_probe_corrected";
inline constexpr std::string_view warnings = "warnings";  ///< the texts, joined by "; "
inline constexpr std::string_view flags = "flags";        ///< the codes, joined by "; "
inline constexpr std::string_view sizes_status = "sizes_status";
inline constexpr std::string_view interfacial_area_source = "interfacial_area_source";
inline constexpr std::string_view awcc_time_scale_ratio = "awcc_time_scale_ratio";
inline constexpr std::string_view awcc_quality_reason = "awcc_quality_reason";
inline constexpr std::string_view awcc_turbulence_measured = "awcc_turbulence_measured";
inline constexpr std::string_view awcc_windows_at_least_lag = "awcc_windows_at_least_lag";
inline constexpr std::string_view awcc_windows_at_greatest_lag = "awcc_windows_at_greatest_lag";
}  // namespace profile_column

}  // namespace awcc
