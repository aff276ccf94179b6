#pragma once
// The texts of a processed recording's warnings of one flag, for tests that
// check what the row's one list says (awcc/assess.hpp).

#include <string>
#include <vector>

#include "awcc/flags.hpp"
#include "awcc/process.hpp"

namespace pdp_test {

/// The texts of a result's signal-check warnings (its flag signal_check).
inline std::vector<std::string> signal_texts(const awcc::ProcessResult& r) {
  std::vector<std::string> out;
  for (const auto& w : r.warnings) {
    if (w.flag == awcc::Flag::signal_check) out.push_back(w.text);
  }
  return out;
}

}  // namespace pdp_test
