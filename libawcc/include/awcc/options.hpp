#pragma once
// The declarations of every option of the processing library
// (awcc/option_field.hpp): name, unit, help, default; and the one way they
// are applied (process_options, method_options), which the pdp command line,
// its settings files and the Python module all use. Fields are applied in
// list order: a later field may read an earlier one (the threshold's meaning
// depends on the rule).

#include <span>
#include <string_view>

#include "awcc/awcc.hpp"
#include "awcc/binarisation.hpp"
#include "awcc/event_detection.hpp"
#include "awcc/fscc.hpp"
#include "awcc/multi_tip.hpp"
#include "awcc/option_field.hpp"
#include "awcc/process.hpp"
#include "awcc/profile_flow.hpp"
#include "awcc/recording.hpp"

namespace awcc {

std::span<const OptionField<ReaderOptions>> reader_option_fields();
std::span<const OptionField<BinarisationOptions>> binarisation_option_fields();
std::span<const OptionField<FsccOptions>> fscc_option_fields();
std::span<const OptionField<AwccOptions>> awcc_option_fields();
/// The options of a whole processing run that belong to none of the above:
/// tip separations, channels, methods, histogram bins.
std::span<const OptionField<ProcessOptions>> process_option_fields();
/// The declaration of the probe's tips among them (tips, leading-tip,
/// tip-channels): the keys a settings file's [probe] table holds.
std::span<const OptionField<ProcessOptions>> probe_option_fields();
std::span<const OptionField<StructureOptions>> structure_option_fields();
/// The multi-tip solvers' options (awcc/multi_tip.hpp).
std::span<const OptionField<MultiTipOptions>> multi_tip_option_fields();
/// Event detection's own options (awcc/event_detection.hpp). Its `roc` and
/// `weighting` are AWCC's declared ones (one switch for both methods, so that
/// their velocities compare like with like): a front end copies them from
/// the AwccOptions it applied, as FSCC takes AWCC's `subsample`.
std::span<const OptionField<EventOptions>> event_option_fields();
/// A profile's flow quantities (awcc/profile_flow.hpp): discharge, invert,
/// depth-levels, flow-draws, flow-seed.
std::span<const OptionField<ProfileFlowOptions>> profile_flow_option_fields();
/// ProfileFlowOptions from settings by their declared names, validated;
/// throws OptionError as process_options does.
ProfileFlowOptions profile_flow_options(std::span<const OptionSetting> settings);

/// A named set of option values (the setting `preset = felder`): applied to
/// the options the user does not give.
struct PresetSetting {
  std::string_view name;   ///< an option's declared name
  std::string_view value;  ///< as a user would type it
};
/// The settings of a preset; throws OptionError (quantity "preset") for an unknown name.
std::span<const PresetSetting> preset_settings(std::string_view name);

/// The options of a processing run from settings by their declared names
/// ({"dx", "7.15mm"}, {"method", "awcc"}); a setting named "preset" names a
/// preset whose values apply to the options not given. Then checked:
/// implausible values unless allow-unusual, then validate(). Throws
/// OptionError whose quantity() is the declared name of the option that
/// fixes it: an unknown name, a refused value (message "[origin: ]name:
/// why"), an implausible value ("allow-unusual") or a combination that
/// cannot work.
ProcessOptions process_options(std::span<const OptionSetting> settings);

/// AWCC's and FSCC's options from settings by their declared names (a
/// study's methods), over `awcc` and `fscc` as given, then validated. Throws
/// OptionError as process_options does. FSCC refines its peak as AWCC does:
/// `subsample` is declared once, with AWCC's options, and this is where FSCC
/// gets it (process_options applies the methods through it too).
void method_options(std::span<const OptionSetting> settings, AwccOptions& awcc, FsccOptions& fscc);

}  // namespace awcc
