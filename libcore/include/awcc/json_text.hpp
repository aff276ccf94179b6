#pragma once
// The text of every JSON output: indented, one trailing line break, and any
// byte that is not UTF-8 (a Latin-1 column name, a file path in another
// encoding) replaced by U+FFFD instead of failing the whole output.

#include <nlohmann/json.hpp>
#include <string>

namespace awcc {

inline std::string json_text(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace awcc
