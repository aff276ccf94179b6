#pragma once
// The bridge from the libraries' option declarations (awcc/option_field.hpp,
// synth::scene_fields) to a subcommand's flags: each declared option becomes
// --name with its help and default; what the user gave (on the command line
// or in the --config file) is applied to an options struct by the same
// declaration. Nothing here restates a default.

#include <CLI/CLI.hpp>
#include <deque>
#include <fmt/format.h>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/option_field.hpp"
#include "awcc/options.hpp"
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
      const std::string unit = f.unit.empty() || f.unit == "-" ? std::string() : fmt::format(", {}", f.unit);
      const std::string help = fmt::format("{}{} [default: {}]", f.help, unit, f.format(defaults));
      if (f.flag) e.option = cmd->add_flag("--" + e.name, e.flag, help);
      else e.option = cmd->add_option("--" + e.name, e.value, help);
      e.option->group(group);
    }
  }

  /// A preset's values (awcc::preset_settings), applied to the options the
  /// user does not give.
  void set_preset(std::string name, std::span<const awcc::PresetSetting> settings) {
    preset_name_ = std::move(name);
    preset_.assign(settings.begin(), settings.end());
  }

  /// Applies every given option of `fields` (or the preset's value, when the
  /// user gave none) to `target`, in declaration order. Throws
  /// std::invalid_argument naming the flag and the problem.
  template <class T>
  void apply(std::span<const awcc::OptionField<T>> fields, T& target) const {
    for (const auto& f : fields) {
      const Entry* e = find(f.name);
      if (!e || e->option->count() == 0) {
        for (const auto& p : preset_) {
          if (p.name != f.name) continue;
          try {
            f.parse(target, p.value);
          } catch (const std::invalid_argument& err) {
            throw std::invalid_argument(fmt::format("--preset {}: --{} {}: {}", preset_name_, f.name, p.value, err.what()));
          }
        }
        continue;
      }
      try {
        f.parse(target, f.flag ? std::string_view(e->flag ? "on" : "off") : std::string_view(e->value));
      } catch (const std::invalid_argument& err) {
        throw std::invalid_argument(fmt::format("{}--{}: {}", origin_of(f.name), f.name, err.what()));
      }
    }
  }

  /// True when the option was given (command line or config file).
  [[nodiscard]] bool given(std::string_view name) const {
    const Entry* e = find(name);
    return e && e->option->count() > 0;
  }

 private:
  struct Entry {
    std::string name, value;
    bool flag = false;
    CLI::Option* option = nullptr;
  };
  [[nodiscard]] const Entry* find(std::string_view name) const {
    for (const auto& e : entries_)
      if (e.name == name) return &e;
    return nullptr;
  }
  std::deque<Entry> entries_;  // stable addresses: CLI11 writes into them
  std::string preset_name_;
  std::vector<awcc::PresetSetting> preset_;
};

}  // namespace pdp
