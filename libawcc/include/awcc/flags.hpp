#pragma once
// The flags of a processed recording: what its reader must know beside its
// numbers (awcc/assess.hpp assembles them). Each warning carries a flag code
// from the table below and a text with advice that fits the row; the same
// text goes to every output (the summary, stderr, the JSON's "warnings" with
// its "flags", the profile CSV's columns of the same names, Python). The
// codes are the table's; a reader of a written file parses them with
// parse_flag (awcc/read_back.hpp).

#include <array>
#include <cstddef>
#include <string>
#include <string_view>

namespace awcc {

enum class Flag {
  reader_note,               ///< the reader accepted the file but says something about it (a cut file, an assumed scale)
  signal_check,              ///< a tip's signal check flagged it, or failed and it was processed anyway
  channels_ignored,          ///< the recording has channels beyond the tip pair processed
  fscc_implausible,          ///< FSCC's velocity is defined but beyond air-water flows
  integral_scale_short,      ///< the velocity's integral time scale is under 2 window durations (error E4)
  integral_scale_undefined,  ///< the velocity's autocorrelation does not reach zero: no time scale
  methods_disagree,          ///< FSCC and AWCC differ by more than their sampling intervals allow
  events_disagree,           ///< event detection's velocity differs from FSCC's (AWCC's) beyond their intervals
  multi_tip_doubtful,        ///< the multi-tip vectors' quality is low (ProbeResult::quality_reason says why)
  arrivals_along_flow,       ///< AWCC's weighting gap says the bubbles arrive spaced along the flow (awcc/weighting_gap.hpp)
  lag_range_end,             ///< AWCC windows peak at an end of the lags the velocity range lets it search (awcc/awcc.hpp)
  tu_not_measured,           ///< every accepted AWCC window peaks at one lag: Tu is not a measurement (awcc/awcc.hpp)
  channels_copied,           ///< two tips hold one signal twice (awcc/process.hpp, copied_channel_correlation)
  long_single_phase,         ///< a tip stays in one phase far longer than its chords allow (awcc/assess.hpp)
};

struct FlagName {
  Flag flag;
  std::string_view code;     ///< as written in the JSON's "flags" and the CSV's flags column
  std::string_view meaning;  ///< one line (docs/output.md, the Python module)
};

/// Every flag in the enum's order: to_string, parse_flag and the lists of
/// codes read this one table.
inline constexpr std::array<FlagName, 14> flag_names{{
    {Flag::reader_note, "reader_note", "the reader accepted the file but notes something about it"},
    {Flag::signal_check, "signal_check",
     "a tip's voltage is not a clean two-level signal of the stated polarity, or its air level is the continuous one"},
    {Flag::channels_ignored, "channels_ignored", "channels beyond the tip pair were not processed"},
    {Flag::fscc_implausible, "fscc_implausible", "FSCC's velocity lies beyond air-water flows"},
    {Flag::integral_scale_short, "integral_scale_short",
     "the velocity's integral time scale is under 2 AWCC window durations: Tu underestimated (error E4)"},
    {Flag::integral_scale_undefined, "integral_scale_undefined",
     "the velocity's autocorrelation does not reach zero: no integral time scale"},
    {Flag::methods_disagree, "methods_disagree",
     "FSCC and AWCC differ by more than their 95 % sampling intervals allow together"},
    {Flag::events_disagree, "events_disagree",
     "event detection's velocity differs from FSCC's (else AWCC's) by more than their 95 % sampling intervals allow"},
    {Flag::multi_tip_doubtful, "multi_tip_doubtful",
     "the multi-tip mean vector is doubtful: it disagrees with FSCC of the tip pair, or the solver's caution is raised"},
    {Flag::arrivals_along_flow, "arrivals_along_flow",
     "AWCC's weighting gap lies above what bubbles arriving in time allow: the correction's prior does not hold"},
    {Flag::lag_range_end, "lag_range_end",
     "AWCC windows peak at an end of the lags the velocity range lets it search: their peaks may lie beyond it"},
    {Flag::tu_not_measured, "tu_not_measured",
     "every accepted AWCC window peaks at one lag: Tu is 0 by the lag's resolution, not measured, and not given"},
    {Flag::channels_copied, "channels_copied",
     "two tips hold one signal twice (a copied channel or cross-talk): what rests on both is not a measurement"},
    {Flag::long_single_phase, "long_single_phase",
     "a tip stays in one phase far longer than its chords allow: the probe out of the flow, a stopped flow or a lost "
     "connection for a while"},
}};
constexpr bool flag_names_in_enum_order() {
  for (std::size_t i = 0; i < flag_names.size(); ++i) {
    if (static_cast<std::size_t>(flag_names[i].flag) != i) return false;
  }
  return static_cast<std::size_t>(Flag::long_single_phase) + 1 == flag_names.size();
}
static_assert(flag_names_in_enum_order(), "a flag added to Flag needs its row in flag_names, in the enum's order");

constexpr std::string_view to_string(Flag flag) { return flag_names[static_cast<std::size_t>(flag)].code; }

/// One entry of a row's list: its flag and the text every output gives.
struct Warning {
  Flag flag = Flag::reader_note;
  std::string text;
  bool operator==(const Warning&) const = default;
};

}  // namespace awcc
