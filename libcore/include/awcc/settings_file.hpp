#pragma once
// Settings files (TOML) as the toolkit reads them, written once: each key
// with its value as the text a user would type after the option of the same
// name. Numbers are written back as TOML gave them ("0.25", "1"), booleans as
// "true"/"false", strings as they are ("5mm"), and arrays as lists: ["a", "b"]
// becomes "a,b" and an array of arrays [[x, y, z], ...] "x,y,z;..." (a list
// of points).

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace awcc {

struct Setting {
  std::string key;
  std::string text;               ///< the value as typed (lists joined as above)
  std::vector<std::string> items; ///< a list's elements (one for a scalar)
  int line = 0;                   ///< where the key is, for messages
};

/// One table of a settings file: "" for the top-level keys.
struct SettingTable {
  std::string name;
  int line = 0;
  std::vector<Setting> settings;
};

/// Every table of a file, the top-level keys first (name ""). Throws
/// InputError naming the file and line: unreadable file, invalid TOML, a
/// table inside a table, a value that is neither a scalar nor a list.
/// A table named in `groups` holds named tables instead of keys (e.g.
/// [conditions.wall], [conditions.upper]): they come as "conditions.wall" ...
std::vector<SettingTable> read_setting_tables(const std::filesystem::path& path,
                                              const std::vector<std::string>& groups = {});

/// The settings of a file: its top-level keys, or when it has a table named
/// `table`, the keys of that table (other tables are refused unless listed in
/// `other_tables`). Throws InputError naming the file and line: unreadable
/// file, invalid TOML, a value that is a table, an unknown table.
std::vector<Setting> read_settings(const std::filesystem::path& path, std::string_view table = {},
                                   const std::vector<std::string>& other_tables = {});

}  // namespace awcc
