#pragma once
// One declaration per option of the libraries: its name (the key in settings
// files; front ends derive their own spelling from it by one rule: the flag
// --name, the Python keyword name_with_underscores), its unit, its help (why
// one would change it) and how it reads and shows its value. The pdp command
// line, settings files and the Python module read these declarations and
// apply what a user gave with apply_settings(); none of them restates a
// default.

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/errors.hpp"

namespace awcc {

template <class Options>
struct OptionField {
  std::string_view name;   ///< "filter-a": the declared name (settings key filter-a, flag --filter-a)
  std::string_view unit;   ///< SI unit of the value ("m", "s", "Hz", "m/s", "V"), "-" dimensionless, "" a choice or text
  std::string_view help;   ///< one line
  /// Sets the option from text as a user types it ("7.15mm", "0.4", "on").
  /// Throws std::invalid_argument naming the problem (not the option).
  void (*parse)(Options&, std::string_view text);
  /// The value as text (the default, for help and provenance).
  std::string (*format)(const Options&);
  bool flag = false;       ///< a switch: given means "true"
};

/// A setting as a user gives it.
struct OptionSetting {
  std::string name;    ///< an option's declared name: "dx"
  std::string value;   ///< as a user types it: "7.15mm"; a switch's "on" / "off"
  std::string origin;  ///< where it was given, for messages: empty (a command line, a call), "FILE:LINE", "preset felder"
};

/// The error for a setting whose value was refused with `why`:
/// "[origin: ]name: why", quantity() the declared name.
inline OptionError setting_error(const OptionSetting& setting, std::string_view why) {
  std::string message = setting.origin.empty() ? std::string() : setting.origin + ": ";
  message += setting.name + ": " + std::string(why);
  return OptionError(message, setting.name);
}

/// Applies each field's setting to `target` in declaration order (a later
/// field may read an earlier one); of several settings of one field the
/// last wins. `used[i]` becomes true for each settings[i] applied (sized as
/// settings). Throws setting_error() for a refused value. `Field` is an
/// OptionField<T> or a field of the same shape (synth::SceneField).
template <class Field, class T>
void apply_settings(std::span<const Field> fields, std::span<const OptionSetting> settings, T& target,
                    std::vector<bool>& used) {
  for (const auto& f : fields) {
    const OptionSetting* given = nullptr;
    for (std::size_t i = 0; i < settings.size(); ++i) {
      if (settings[i].name != f.name) continue;
      given = &settings[i];
      used[i] = true;
    }
    if (!given) continue;
    try {
      f.parse(target, given->value);
    } catch (const std::invalid_argument& e) {
      throw setting_error(*given, e.what());
    }
  }
}

}  // namespace awcc
