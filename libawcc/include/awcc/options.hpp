#pragma once
// The declarations of every option of the processing library
// (awcc/option_field.hpp): name, unit, help, default. The pdp command line,
// settings files and the Python module register and read options from these
// lists and restate none of them. Apply fields in list order: a later field
// may read an earlier one (the threshold's meaning depends on the rule).
// After applying AWCC's fields, FSCC refines its peak as AWCC does
// (`subsample` is declared once, with AWCC's options).

#include <span>
#include <string_view>

#include "awcc/awcc.hpp"
#include "awcc/binarisation.hpp"
#include "awcc/fscc.hpp"
#include "awcc/option_field.hpp"
#include "awcc/process.hpp"
#include "awcc/recording.hpp"

namespace awcc {

std::span<const OptionField<ReaderOptions>> reader_option_fields();
std::span<const OptionField<BinarisationOptions>> binarisation_option_fields();
std::span<const OptionField<FsccOptions>> fscc_option_fields();
std::span<const OptionField<AwccOptions>> awcc_option_fields();
/// The options of a whole processing run that belong to none of the above:
/// tip separations, channels, methods, histogram bins.
std::span<const OptionField<ProcessOptions>> process_option_fields();
std::span<const OptionField<StructureOptions>> structure_option_fields();

/// A named set of option values (`--preset felder`): applied before what the
/// user gives, which overrides it.
struct PresetSetting {
  std::string_view name;   ///< an option's declared name
  std::string_view value;  ///< as a user would type it
};
/// The settings of a preset; throws std::invalid_argument for an unknown name.
std::span<const PresetSetting> preset_settings(std::string_view name);

/// A setting as a user types it: {"dx", "7.15mm"}, {"method", "awcc"}.
struct OptionSetting {
  std::string name;
  std::string value;
};
/// The options of a processing run from settings by their declared names, a
/// preset's values first for the options not given (as `pdp process`
/// applies them, in the same order), then checked: implausible values unless
/// allow-unusual, then validate(). Throws OptionError naming the option
/// (quantity() = its name) for an unknown name, a bad value or an
/// implausible one, std::invalid_argument for a combination that cannot work.
ProcessOptions process_options(std::span<const OptionSetting> settings, std::string_view preset = {});

}  // namespace awcc
