#include "arguments.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

namespace pdp {

namespace {

// Optimal string alignment distance: a typo is an insertion, a deletion, a
// substitution or two neighbours swapped, each one edit.
std::size_t distance(std::string_view a, std::string_view b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[a.size()][b.size()];
}

// An argument that is an option: -x or --xyz, not "--" (the end of
// options), "-" (stdin) or a negative number ("-1mm", "-.5").
bool looks_like_option(const std::string& a) {
  if (a.size() < 2 || a[0] != '-' || a == "--") return false;
  const char c = a[1] == '-' ? (a.size() > 2 ? a[2] : '\0') : a[1];
  return std::isalpha(static_cast<unsigned char>(c)) != 0;
}

// How an argument reads in `app`: whether it names its options (--name,
// --name=value, -x, -xVALUE, short flags together: -qo FILE), and whether
// the next argument is a value.
struct Reading {
  bool known = false;
  bool value_follows = false;
};

bool takes_value(const CLI::Option* o) {
  return o->get_items_expected_max() > 0;
}

Reading read_argument(const CLI::App& app, const std::string& a) {
  if (a[1] == '-') {
    const auto* o = app.get_option_no_throw(a.substr(0, a.find('=')));
    return {o != nullptr, o && takes_value(o) && a.find('=') == std::string::npos};
  }
  for (std::size_t k = 1; k < a.size(); ++k) {
    const auto* o = app.get_option_no_throw(std::string{'-', a[k]});
    if (!o) return {};
    if (takes_value(o)) return {true, k + 1 == a.size()};  // the rest of the argument, or the next, is its value
  }
  return {true, false};
}

// The long flags: what a typo is measured against (a one-letter flag is one
// edit from every other).
std::vector<std::string> flags_of(const CLI::App& app) {
  std::vector<std::string> names;
  for (const auto* o : app.get_options()) {
    for (const auto& l : o->get_lnames()) names.push_back("--" + l);
  }
  return names;
}

std::string command_of(const CLI::App& app) {
  return app.get_parent() ? "pdp " + app.get_name() : std::string("pdp");
}

[[noreturn]] void unknown_option(const std::string& a, const CLI::App& app) {
  const std::string name = a.substr(0, a.find('='));
  throw std::invalid_argument(fmt::format("unknown option {} for {}{} ({} --help lists its options)", name,
                                          command_of(app), did_you_mean(name, flags_of(app)), command_of(app)));
}

}  // namespace

std::vector<std::string> nearest_names(std::string_view typed, const std::vector<std::string>& known) {
  const auto bare = [](std::string_view s) {
    while (!s.empty() && s.front() == '-') s.remove_prefix(1);
    return s;
  };
  const std::string_view t = bare(typed);
  const std::size_t most = 1 + t.size() / 4;
  std::size_t best = most + 1;
  std::vector<std::string> out;
  for (const auto& k : known) {
    const std::size_t d = distance(t, bare(k));
    if (d > most || d > best) continue;
    if (d < best) out.clear();
    best = d;
    if (std::find(out.begin(), out.end(), k) == out.end()) out.push_back(k);
  }
  return out;
}

std::string did_you_mean(std::string_view typed, const std::vector<std::string>& known, std::string_view prefix) {
  const auto near = nearest_names(typed, known);
  if (near.empty()) return {};
  std::string list;
  for (std::size_t i = 0; i < near.size() && i < 3; ++i) {
    list += fmt::format("{}{}{}", i == 0 ? "" : (i + 1 == std::min<std::size_t>(near.size(), 3) ? " or " : ", "),
                        prefix, near[i]);
  }
  return fmt::format(": did you mean {}?", list);
}

std::vector<std::string> arrange_arguments(const CLI::App& app, const std::vector<std::string>& arguments) {
  const auto subcommands = app.get_subcommands([](const CLI::App*) { return true; });
  const CLI::App* sub = nullptr;
  std::size_t at = 0;  // the subcommand's argument
  for (; at < arguments.size(); ++at) {
    const std::string& a = arguments[at];
    if (a == "--") break;
    if (looks_like_option(a)) {
      const Reading r = read_argument(app, a);
      if (!r.known) {
        // An option of the subcommand (or of another) before it: said so, not taken for a typo.
        const std::string name = a.substr(0, a.find('='));
        for (std::size_t k = at + 1; k < arguments.size(); ++k) {
          for (const auto* s : subcommands) {
            if (s->get_name() == arguments[k] && read_argument(*s, a).known) {
              throw std::invalid_argument(
                  fmt::format("{} is an option of pdp {}: give it after '{}'", name, s->get_name(), s->get_name()));
            }
          }
        }
        std::vector<std::string> owners;
        for (const auto* s : subcommands) {
          if (read_argument(*s, a).known) owners.push_back("pdp " + s->get_name());
        }
        if (!owners.empty()) {
          throw std::invalid_argument(fmt::format("{} is an option of {}, not of pdp itself: give it after the command",
                                                  name, fmt::join(owners, ", ")));
        }
        unknown_option(a, app);
      }
      if (r.value_follows) ++at;
      continue;
    }
    for (const auto* s : subcommands) {
      if (s->get_name() == a) sub = s;
    }
    if (!sub) {
      std::vector<std::string> names;
      for (const auto* s : subcommands) names.push_back(s->get_name());
      throw std::invalid_argument(
          fmt::format("unknown command '{}'{} (pdp --help lists the commands)", a, did_you_mean(a, names)));
    }
    break;
  }
  // No subcommand (CLI11 says one is required), or one that hands its arguments on (pdp report).
  if (!sub || sub->get_prefix_command()) return arguments;
  std::vector<std::string> before(arguments.begin(), arguments.begin() + static_cast<std::ptrdiff_t>(at));
  std::vector<std::string> after{arguments[at]};
  for (std::size_t i = at + 1; i < arguments.size(); ++i) {
    const std::string& a = arguments[i];
    if (a == "--") {
      after.insert(after.end(), arguments.begin() + static_cast<std::ptrdiff_t>(i), arguments.end());
      break;
    }
    if (!looks_like_option(a)) {
      after.push_back(a);
      continue;
    }
    const bool last = i + 1 == arguments.size();
    if (const Reading r = read_argument(*sub, a); r.known) {
      after.push_back(a);
      if (r.value_follows && !last) after.push_back(arguments[++i]);
      continue;
    }
    // pdp's own options work after the subcommand too.
    if (const Reading r = read_argument(app, a); r.known) {
      before.push_back(a);
      if (r.value_follows && !last) before.push_back(arguments[++i]);
      continue;
    }
    std::error_code ec;
    if (std::filesystem::exists(a, ec)) {
      after.push_back(a);  // a file named like an option
      continue;
    }
    unknown_option(a, *sub);
  }
  before.insert(before.end(), after.begin(), after.end());
  return before;
}

}  // namespace pdp
