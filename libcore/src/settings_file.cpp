#include "awcc/settings_file.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>

#include "awcc/errors.hpp"

namespace awcc {

namespace {

std::string scalar_text(const toml::node& node) {
  if (const auto* s = node.as_string()) return std::string(s->get());
  if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
  if (const auto* d = node.as_floating_point()) return fmt::format("{}", d->get());
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  throw std::invalid_argument("must be a number, a string, a boolean or a list of them");
}

Setting setting_of(const std::string& key, const toml::node& node) {
  Setting s;
  s.key = key;
  s.line = static_cast<int>(node.source().begin.line);
  if (const auto* a = node.as_array()) {
    for (const auto& element : *a) {
      if (const auto* inner = element.as_array()) {
        std::string point;
        for (const auto& c : *inner) point += (point.empty() ? "" : ",") + scalar_text(c);
        s.items.push_back(point);
      } else {
        s.items.push_back(scalar_text(element));
      }
    }
    const bool points = !a->empty() && (*a)[0].is_array();
    for (const auto& item : s.items) s.text += (s.text.empty() ? "" : (points ? ";" : ",")) + item;
  } else {
    s.text = scalar_text(node);
    s.items = {s.text};
  }
  return s;
}

toml::table parse(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(fmt::format("{}: no such settings file; check the path", path.string()));
  }
  try {
    return toml::parse_file(path.string());
  } catch (const toml::parse_error& e) {
    const auto& where = e.source().begin;
    throw InputError(
        fmt::format("{}:{}:{}: not valid TOML: {}", path.string(), where.line, where.column, e.description()));
  }
}

std::vector<Setting> settings_of(const std::filesystem::path& path, const toml::table& t, bool top) {
  std::vector<Setting> out;
  for (const auto& [key, node] : t) {
    const std::string k(key.str());
    if (node.is_table()) {
      if (top) continue;
      throw InputError(fmt::format("{}:{}: [{}] is a table inside a table; settings files have one level of tables",
                                   path.string(), node.source().begin.line, k));
    }
    try {
      out.push_back(setting_of(k, node));
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}:{}: {} {}", path.string(), node.source().begin.line, k, e.what()));
    }
  }
  return out;
}

}  // namespace

std::vector<SettingTable> read_setting_tables(const std::filesystem::path& path, const std::vector<std::string>& groups) {
  const toml::table t = parse(path);
  std::vector<SettingTable> out{{"", 1, settings_of(path, t, true)}};
  for (const auto& [key, node] : t) {
    const auto* inner = node.as_table();
    if (!inner) continue;
    const std::string name(key.str());
    if (std::find(groups.begin(), groups.end(), name) == groups.end()) {
      out.push_back({name, static_cast<int>(node.source().begin.line), settings_of(path, *inner, false)});
      continue;
    }
    std::vector<SettingTable> members;
    for (const auto& [member, member_node] : *inner) {
      const auto* table = member_node.as_table();
      if (!table) {
        throw InputError(fmt::format("{}:{}: {}.{} is not a table; write [{}.NAME] tables of settings", path.string(),
                                     member_node.source().begin.line, name, member.str(), name));
      }
      members.push_back({name + "." + std::string(member.str()), static_cast<int>(member_node.source().begin.line),
                         settings_of(path, *table, false)});
    }
    // In the file's order (the parser keeps them sorted by name).
    std::stable_sort(members.begin(), members.end(),
                     [](const SettingTable& a, const SettingTable& b) { return a.line < b.line; });
    out.insert(out.end(), members.begin(), members.end());
  }
  return out;
}

std::vector<Setting> read_settings(const std::filesystem::path& path, std::string_view table,
                                   const std::vector<std::string>& other_tables) {
  const auto tables = read_setting_tables(path);
  const SettingTable* chosen = &tables.front();
  for (const auto& t : tables) {
    if (t.name.empty()) continue;
    if (!table.empty() && t.name == table) {
      chosen = &t;
      continue;
    }
    if (std::find(other_tables.begin(), other_tables.end(), t.name) != other_tables.end()) continue;
    throw InputError(fmt::format("{}:{}: unknown table [{}]{}", path.string(), t.line, t.name,
                                 table.empty() ? "" : fmt::format("; use top-level keys or [{}]", table)));
  }
  if (chosen != &tables.front() && !tables.front().settings.empty()) {
    const auto& stray = tables.front().settings.front();
    throw InputError(fmt::format("{}:{}: {} stands outside [{}]; put every setting in the table", path.string(),
                                 stray.line, stray.key, table));
  }
  return chosen->settings;
}

}  // namespace awcc
