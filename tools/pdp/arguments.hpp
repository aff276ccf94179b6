#pragma once
// The command line read once before CLI11 parses it, for what CLI11 2.1
// answers with the wrong message: an unknown option of a subcommand is
// taken for a stray word and its value for a file ("files: Path does not
// exist: 3" for `--nq 3`), and an option of pdp itself after the
// subcommand (`pdp process f --log-level debug`) likewise. Here an unknown
// option is named as one, with the nearest known names; pdp's own options
// work before or after the subcommand.

#include <CLI/CLI.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace pdp {

/// The arguments (without the program name) to parse: those of pdp's own
/// options given after the subcommand moved before it, the rest in their
/// order. Throws std::invalid_argument for an unknown option (one starting
/// with - that no option of pdp or of its subcommand has, and that is not an
/// existing path) or an unknown subcommand, naming it and the nearest known
/// ones.
std::vector<std::string> arrange_arguments(const CLI::App& app, const std::vector<std::string>& arguments);

/// The known names nearest `typed` (edit distance, at most 1 + a quarter of
/// its length), best first: the suggestions of "did you mean".
std::vector<std::string> nearest_names(std::string_view typed, const std::vector<std::string>& known);

/// "; did you mean A or B?" from nearest_names, `prefix` before each
/// name ("--" for flags); empty when none is near.
std::string did_you_mean(std::string_view typed, const std::vector<std::string>& known, std::string_view prefix = "");

}  // namespace pdp
