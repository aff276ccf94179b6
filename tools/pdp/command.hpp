#pragma once
// What every pdp subcommand shares: its --config settings file (the same
// names as its flags; the command line wins; CLI11 2.1 reads no config for
// subcommands, so it is applied here), its required arguments (checked after
// the file is applied, so that a file may give them), and the exit codes of
// the table of docs/guide/settings.md.

#include <CLI/CLI.hpp>
#include <exception>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pdp {

/// The documented exit codes (docs/guide/settings.md, "Exit status").
enum ExitCode : int {
  exit_ok = 0,
  exit_bad_input = 1,     ///< input data that cannot be used (a recording, model or results file)
  exit_bad_usage = 2,     ///< bad options or arguments, including a missing or unreadable config file
  exit_output_failed = 3, ///< an output could not be written
  exit_internal = 4,      ///< a defect of pdp: please report it
  exit_missing_helper = 5,  ///< a program or package pdp runs is missing (pdp report: Python, matplotlib, Jinja2)
};

struct Command {
  CLI::App* app = nullptr;
  std::string config;                  ///< --config FILE.toml
  std::vector<CLI::Option*> required;  ///< given on the command line or in the config file
  /// A settings file's tables that hold some of this command's options
  /// beside its own ([probe]: the tips), each with the names it may hold.
  std::vector<std::pair<std::string, std::vector<std::string>>> option_tables;
};

/// Adds --config to the subcommand.
void add_config_option(Command& command);
/// Declares that an option's values are paths (inputs or outputs): given in
/// a settings file, a relative path is taken from the settings file's
/// folder, as one typed on the command line is from the current folder.
/// Returns the option.
CLI::Option* path_option(CLI::Option* option);
/// Applies the config file's settings to the options not given on the command
/// line, then checks the required ones. Throws std::invalid_argument naming
/// the file, the line and the setting.
void finish_parsing(Command& command);

/// Logs the error (with the flag that fixes it, when the error names an
/// option of the running command) and returns its exit code.
int report_error(const std::exception& error);

/// The flag of a declared option: "--" + its name. The one place the command
/// line spells a library's option names.
std::string flag_of(std::string_view name);

/// "FILE:LINE" when the option `name` (without --) was given by a config
/// file, else empty: errors found later name where the value came from.
std::string origin_of(std::string_view name);

/// The command line as typed (each argument quoted when it needs it), for
/// the provenance of outputs; set once by main().
void set_command_line(int argc, char** argv);
const std::string& command_line();

/// The flag(s) of an error's quantity, "--fs" or "--leading-channel/--trailing-channel"
/// (a quantity names one declared option or several, comma-separated); only
/// flags of the running command; empty when it has none.
std::string flags_for(std::string_view quantity);

/// A message of several lines (a scene's problems) on one log line, "; " between them.
std::string one_line(std::string text);

}  // namespace pdp
