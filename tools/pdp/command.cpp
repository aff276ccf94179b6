#include "command.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <map>
#include <set>

#include "arguments.hpp"
#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/settings_file.hpp"

namespace pdp {

namespace {
// Where each option given by a config file came from (one process, one command).
std::map<std::string, std::string, std::less<>>& origins() {
  static std::map<std::string, std::string, std::less<>> map;
  return map;
}
// The options whose values are paths (path_option).
std::set<const CLI::Option*>& path_options() {
  static std::set<const CLI::Option*> set;
  return set;
}
// The command being run (one process, one command): errors name only its flags.
const CLI::App*& running() {
  static const CLI::App* app = nullptr;
  return app;
}
}  // namespace

namespace {
std::string& the_command_line() {
  static std::string text;
  return text;
}
}  // namespace

void set_command_line(int argc, char** argv) {
  std::string text;
  for (int i = 0; i < argc; ++i) {
    std::string a = argv[i];
    const bool plain = !a.empty() && a.find_first_of(" \t\"'\\$`;&|<>*?()") == std::string::npos;
    if (!plain) {
      std::string q = "'";
      for (char c : a) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
      a = q + "'";
    }
    text += (i ? " " : "") + a;
  }
  the_command_line() = text;
}

const std::string& command_line() { return the_command_line(); }

std::string flag_of(std::string_view name) { return "--" + std::string(name); }

std::string origin_of(std::string_view name) {
  const auto it = origins().find(name);
  return it == origins().end() ? std::string() : it->second;
}

void add_config_option(Command& c) {
  c.app->add_option("--config", c.config,
                    "settings file (TOML): keys are these options' names without --, at the top level or in a [" +
                        c.app->get_name() + "] table; the command line overrides it");
}

CLI::Option* path_option(CLI::Option* option) {
  path_options().insert(option);
  return option;
}

namespace {
// A settings file's path value, relative to the file's folder (absolute ones as they are).
std::string from_settings_folder(const std::string& config, const std::string& value) {
  const std::filesystem::path p(value);
  if (value.empty() || p.is_absolute()) return value;
  return (std::filesystem::path(config).parent_path() / p).lexically_normal().string();
}
}  // namespace

void finish_parsing(Command& c) {
  running() = c.app;
  if (!c.config.empty()) {
    std::vector<awcc::Setting> settings;
    try {
      // One file may hold the settings of several subcommands, a table each.
      std::vector<std::string> others;
      if (auto* parent = c.app->get_parent()) {
        for (const auto* sub : parent->get_subcommands([](const CLI::App*) { return true; })) {
          others.push_back(sub->get_name());
        }
      }
      for (const auto& [table, names] : c.option_tables) others.push_back(table);
      settings = awcc::read_settings(c.config, c.app->get_name(), others);
      if (!c.option_tables.empty()) {
        for (const auto& t : awcc::read_setting_tables(c.config)) {
          const auto held = std::find_if(c.option_tables.begin(), c.option_tables.end(),
                                         [&t](const auto& x) { return x.first == t.name; });
          if (held == c.option_tables.end()) continue;
          for (const auto& s : t.settings) {
            const auto& names = held->second;
            if (std::find(names.begin(), names.end(), s.key) == names.end()) {
              std::string listed;
              for (const auto& n : names) listed += (listed.empty() ? "" : ", ") + n;
              throw awcc::InputError(fmt::format("{}:{}: [{}] holds {}; '{}' belongs at the top level or in [{}]",
                                                 c.config, s.line, t.name, listed, s.key, c.app->get_name()));
            }
            const auto twice = std::find_if(settings.begin(), settings.end(),
                                            [&s](const awcc::Setting& x) { return x.key == s.key; });
            if (twice != settings.end()) {
              throw awcc::InputError(fmt::format("{}:{}: {} is given again in [{}] (line {}); keep one", c.config,
                                                 twice->line, s.key, t.name, s.line));
            }
            settings.push_back(s);
          }
        }
      }
    } catch (const awcc::InputError& e) {
      throw std::invalid_argument(std::string("--config: ") + e.what());
    }
    for (const auto& s : settings) {
      CLI::Option* option = c.app->get_option_no_throw("--" + s.key);
      if (!option) option = c.app->get_option_no_throw(s.key);  // a positional argument by name
      if (!option || s.key == "config" || s.key == "help") {
        std::vector<std::string> names;
        for (const auto* o : c.app->get_options()) {
          for (const auto& l : o->get_lnames()) names.push_back(l);
          if (o->get_lnames().empty() && o->get_snames().empty()) names.push_back(o->get_name(true));  // positional
        }
        std::erase_if(names, [](const std::string& n) { return n == "config" || n == "help"; });
        const auto near = did_you_mean(s.key, names);
        throw std::invalid_argument(fmt::format(
            "{}:{}: unknown setting '{}' for pdp {}{}{}", c.config, s.line, s.key, c.app->get_name(), near,
            near.empty() ? fmt::format("; use the names of pdp {} --help", c.app->get_name()) : std::string()));
      }
      if (option->count() > 0) continue;  // the command line wins
      const bool path = path_options().count(option) > 0;
      try {
        if (option->get_items_expected_max() > 1) {
          for (const auto& item : s.items) option->add_result(path ? from_settings_folder(c.config, item) : item);
        } else {
          option->add_result(path ? from_settings_folder(c.config, s.text) : s.text);
        }
        option->run_callback();
        origins()[s.key] = fmt::format("{}:{}", c.config, s.line);
      } catch (const CLI::Error& e) {
        throw std::invalid_argument(fmt::format("{}:{}: {}: {}", c.config, s.line, s.key, e.what()));
      }
    }
  }
  for (CLI::Option* option : c.required) {
    if (option->count() == 0) {
      // A command whose --config is its input (pdp design) has no settings file.
      const bool settings_file = option->get_name() != "--config";
      throw std::invalid_argument(fmt::format("{} is required{}; see pdp {} --help", option->get_name(),
                                              settings_file ? " (on the command line or in --config)" : "",
                                              c.app->get_name()));
    }
  }
}

namespace {

std::string with_flag(const std::string& message, std::string_view quantity) {
  const auto flags = flags_for(quantity);
  return flags.empty() ? message : fmt::format("{} ({})", message, flags);
}

}  // namespace

std::string flags_for(std::string_view quantity) {
  std::string out;
  for (const auto& name : awcc::split_cells(quantity)) {
    if (name.empty() || !running() || !running()->get_option_no_throw(flag_of(name))) continue;
    out += (out.empty() ? "" : "/") + flag_of(name);
  }
  return out;
}

std::string one_line(std::string text) {
  for (auto at = text.find('\n'); at != std::string::npos; at = text.find('\n', at)) text.replace(at, 1, "; ");
  return text;
}

int report_error(const std::exception& error) {
  if (const auto* e = dynamic_cast<const awcc::OptionError*>(&error)) {
    spdlog::error("{}", with_flag(e->what(), e->quantity()));
    return exit_bad_usage;
  }
  if (dynamic_cast<const std::invalid_argument*>(&error)) {
    spdlog::error("{}", error.what());
    return exit_bad_usage;
  }
  if (const auto* e = dynamic_cast<const awcc::InputError*>(&error)) {
    spdlog::error("{}", with_flag(e->what(), e->quantity()));
    return exit_bad_input;
  }
  if (dynamic_cast<const awcc::OutputError*>(&error) || dynamic_cast<const std::filesystem::filesystem_error*>(&error)) {
    spdlog::error("{}", error.what());
    return exit_output_failed;
  }
  if (dynamic_cast<const std::runtime_error*>(&error)) {
    spdlog::error("{}", error.what());
    return exit_bad_input;
  }
  spdlog::error("internal error: {}; please report it with the command line", error.what());
  return exit_internal;
}

}  // namespace pdp
