#include "report_command.hpp"

#include <fmt/format.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <vector>

extern char** environ;

namespace pdp {

namespace fs = std::filesystem;

namespace {

constexpr const char* install_help =
    "pdp report draws with Python 3, matplotlib and Jinja2: install Debian's python3, python3-matplotlib and "
    "python3-jinja2 (sudo apt install python3 python3-matplotlib python3-jinja2)";

// Debian's /usr/bin/python3 carries the NumPy the module was built with; the
// first python3 on PATH may be another interpreter. PDP_PYTHON overrides.
std::optional<std::string> find_python() {
  if (const char* chosen = std::getenv("PDP_PYTHON"); chosen && *chosen) return std::string(chosen);
  if (fs::exists("/usr/bin/python3")) return std::string("/usr/bin/python3");
  if (const char* path = std::getenv("PATH")) {
    std::string_view rest(path);
    while (!rest.empty()) {
      const auto colon = rest.find(':');
      const fs::path candidate = fs::path(std::string(rest.substr(0, colon))) / "python3";
      std::error_code ec;
      if (fs::is_regular_file(candidate, ec)) return candidate.string();
      rest = colon == std::string_view::npos ? std::string_view() : rest.substr(colon + 1);
    }
  }
  return std::nullopt;
}

// The package sits beside this executable: build/python in the build tree
// (pdp is build/tools/pdp), PREFIX/<site-packages> when installed.
std::vector<fs::path> module_candidates() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  std::vector<fs::path> dirs;
  if (ec) return dirs;
  dirs.push_back(exe.parent_path().parent_path() / "python");
#ifdef PDP_PYTHON_INSTALL_DIR
  dirs.push_back(exe.parent_path().parent_path() / PDP_PYTHON_INSTALL_DIR);
#endif
  return dirs;
}

}  // namespace

int write_report(std::vector<std::string> arguments, const std::string& script) {
  const auto python = find_python();
  if (!python) {
    spdlog::error("no python3 found (PDP_PYTHON, /usr/bin/python3, PATH): {}", install_help);
    return exit_missing_helper;
  }
  std::optional<fs::path> module_dir;
  std::string looked;
  for (const auto& dir : module_candidates()) {
    std::error_code ec;
    if (fs::is_regular_file(dir / "pdp" / script, ec)) {
      module_dir = dir;
      break;
    }
    looked += (looked.empty() ? "" : ", ") + dir.lexically_normal().string();
  }
  if (!module_dir) {
    spdlog::error("the pdp Python module is not beside this pdp (looked in {}): build pdp with its Python module "
                  "(Debian's pybind11-dev, python3-dev and python3-numpy) or install it with cmake --install",
                  looked.empty() ? "no folder: the executable's path is unknown" : looked);
    return exit_missing_helper;
  }
  // Run as a script, not -m: its own first lines check the packages and say
  // what to install before anything imports them.
  std::vector<std::string> args = {*python, (*module_dir / "pdp" / script).string(), "--command-line",
                                   command_line()};
  args.insert(args.end(), arguments.begin(), arguments.end());
  std::vector<std::string> env;
  std::string pythonpath = "PYTHONPATH=" + module_dir->string();
  for (char** e = environ; *e; ++e) {
    if (std::strncmp(*e, "PYTHONPATH=", 11) == 0) pythonpath += std::string(":") + (*e + 11);
    else env.emplace_back(*e);
  }
  env.push_back(pythonpath);
  std::vector<char*> argv, envp;
  for (auto& a : args) argv.push_back(a.data());
  for (auto& e : env) envp.push_back(e.data());
  argv.push_back(nullptr);
  envp.push_back(nullptr);

  spdlog::debug("running {}", fmt::join(args, " "));
  pid_t pid = 0;
  if (const int err = posix_spawn(&pid, python->c_str(), nullptr, nullptr, argv.data(), envp.data()); err != 0) {
    spdlog::error("cannot run {}: {}; {}", *python, std::strerror(err), install_help);
    return exit_missing_helper;
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      spdlog::error("internal error: waiting for {}: {}; please report it with the command line", *python,
                    std::strerror(errno));
      return exit_internal;
    }
  }
  if (WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    if (code >= exit_ok && code <= exit_missing_helper) return code;  // pdp.report speaks the same table
    spdlog::error("internal error: pdp/{} ended with exit status {}; please report it with the command line", script,
                  code);
    return exit_internal;
  }
  spdlog::error("internal error: pdp/{} was killed by signal {}; please report it with the command line", script,
                WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return exit_internal;
}

void setup_report(CLI::App& app, Command& command, ReportOptions& o) {
  auto* cmd = app.add_subcommand("report",
                                 "One self-contained HTML page for a pdp process JSON: profile figures, per-position "
                                 "figures, the profile table with units, warnings, gaps and provenance (pdp report "
                                 "--help lists its options)");
  command.app = cmd;
  // Every argument, --help included, goes to pdp.report, which declares them.
  cmd->prefix_command();
  cmd->set_help_flag();
  cmd->callback([cmd, &o] { o.arguments = cmd->remaining(); });
}

int run_report(const ReportOptions& o) { return write_report(o.arguments); }

}  // namespace pdp
