#pragma once
// The bridge from the libraries' option declarations (awcc/option_field.hpp)
// to a subcommand's flags: each declared option becomes --name with its help
// and default; what the user gave (on the command line or in the --config
// file) is collected as settings by declared name, with where each came
// from, for the libraries to apply (awcc::process_options,
// awcc::method_options, awcc::apply_settings). Nothing here restates a
// default or applies a value.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <deque>
#include <fmt/format.h>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/option_field.hpp"
#include "command.hpp"

namespace pdp {

class OptionSet {
 public:
  /// Registers `fields` on `cmd` (all, or only those named in `only`), their
  /// defaults shown from `defaults`.
  template <class T>
  void add(CLI::App* cmd, std::span<const awcc::OptionField<T>> fields, const T& defaults, const std::string& group,
           const std::vector<std::string_view>& only = {}) {
    for (const auto& f : fields) {
      if (!only.empty() && std::find(only.begin(), only.end(), f.name) == only.end()) continue;
      auto& e = entries_.emplace_back();
      e.name = std::string(f.name);
      e.is_switch = f.flag;
      const std::string unit = f.unit.empty() || f.unit == "-" ? std::string() : fmt::format(", {}", f.unit);
      const std::string help = fmt::format("{}{} [default: {}]", f.help, unit, f.format(defaults));
      if (f.flag) e.option = cmd->add_flag(flag_of(e.name), e.flag, help);
      else e.option = cmd->add_option(flag_of(e.name), e.value, help);
      e.option->group(group);
    }
  }

  /// What the user gave (command line or config file), in registration
  /// order: a switch as "on" / "off", the origin of a config file's value.
  [[nodiscard]] std::vector<awcc::OptionSetting> settings() const {
    std::vector<awcc::OptionSetting> out;
    for (const auto& e : entries_) {
      if (e.option->count() == 0) continue;
      out.push_back({e.name, e.is_switch ? std::string(e.flag ? "on" : "off") : e.value, origin_of(e.name)});
    }
    return out;
  }

  /// True when the option was given (command line or config file).
  [[nodiscard]] bool given(std::string_view name) const {
    for (const auto& e : entries_)
      if (e.name == name) return e.option->count() > 0;
    return false;
  }

 private:
  struct Entry {
    std::string name, value;
    bool flag = false;       // a switch's value
    bool is_switch = false;
    CLI::Option* option = nullptr;
  };
  std::deque<Entry> entries_;  // stable addresses: CLI11 writes into them
};

}  // namespace pdp
