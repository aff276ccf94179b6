#pragma once
// One declaration per option of the libraries: its name (the command-line
// flag without "--" and the key in settings files), its unit, its help (why
// one would change it) and how it reads and shows its value. The pdp command
// line, settings files and the Python module read these declarations; none of
// them restates a default.

#include <string>
#include <string_view>

namespace awcc {

template <class Options>
struct OptionField {
  std::string_view name;   ///< "filter-a": the flag --filter-a and the settings key filter-a
  std::string_view unit;   ///< SI unit of the value ("m", "s", "Hz", "m/s", "V"), "-" dimensionless, "" a choice or text
  std::string_view help;   ///< one line
  /// Sets the option from text as a user types it ("7.15mm", "0.4", "on").
  /// Throws std::invalid_argument naming the problem (not the flag).
  void (*parse)(Options&, std::string_view text);
  /// The value as text (the default, for help and provenance).
  std::string (*format)(const Options&);
  bool flag = false;       ///< a switch: given means "true"
};

}  // namespace awcc
