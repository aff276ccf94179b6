#include "awcc/mat_output.hpp"

#include <fmt/format.h>
#include <matio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include "awcc/atomic_output.hpp"
#include "awcc/errors.hpp"

namespace awcc {

namespace {

using nlohmann::json;

struct VarFree {
  void operator()(matvar_t* v) const noexcept { Mat_VarFree(v); }
};
using Var = std::unique_ptr<matvar_t, VarFree>;

struct MatClose {
  void operator()(mat_t* m) const noexcept { Mat_Close(m); }
};

// Version 5 holds a variable of at most 2^31 - 1 bytes.
constexpr double kVersion5Bytes = 2147483647.0;

Var checked(matvar_t* v, std::string_view what) {
  if (!v) throw std::runtime_error(fmt::format("matio could not create {}", what));
  return Var(v);
}

Var doubles(const char* name, const std::vector<double>& values, std::size_t rows, std::size_t columns) {
  std::size_t dims[2] = {rows, columns};
  auto* data = const_cast<double*>(values.empty() ? nullptr : values.data());
  return checked(Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, data, 0), "a double array");
}

Var empty(const char* name) { return doubles(name, {}, 0, 0); }

Var logicals(const char* name, const std::vector<std::uint8_t>& values) {
  std::size_t dims[2] = {1, values.size()};
  auto* data = const_cast<std::uint8_t*>(values.data());
  return checked(Mat_VarCreate(name, MAT_C_UINT8, MAT_T_UINT8, 2, dims, data, MAT_F_LOGICAL), "a logical array");
}

// UTF-8 to UTF-16 code units: MATLAB's char (a malformed byte becomes U+FFFD).
std::vector<std::uint16_t> utf16(const std::string& s) {
  std::vector<std::uint16_t> out;
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::uint32_t cp = 0xFFFD;
    std::size_t n = 1;
    if (c < 0x80) {
      cp = c;
    } else if ((c >> 5) == 0x6 && i + 1 < s.size()) {
      cp = ((c & 0x1Fu) << 6) | (static_cast<unsigned char>(s[i + 1]) & 0x3Fu);
      n = 2;
    } else if ((c >> 4) == 0xE && i + 2 < s.size()) {
      cp = ((c & 0x0Fu) << 12) | ((static_cast<unsigned char>(s[i + 1]) & 0x3Fu) << 6) |
           (static_cast<unsigned char>(s[i + 2]) & 0x3Fu);
      n = 3;
    } else if ((c >> 3) == 0x1E && i + 3 < s.size()) {
      cp = ((c & 0x07u) << 18) | ((static_cast<unsigned char>(s[i + 1]) & 0x3Fu) << 12) |
           ((static_cast<unsigned char>(s[i + 2]) & 0x3Fu) << 6) | (static_cast<unsigned char>(s[i + 3]) & 0x3Fu);
      n = 4;
    }
    if (cp >= 0x10000) {
      cp -= 0x10000;
      out.push_back(static_cast<std::uint16_t>(0xD800 + (cp >> 10)));
      out.push_back(static_cast<std::uint16_t>(0xDC00 + (cp & 0x3FF)));
    } else {
      out.push_back(static_cast<std::uint16_t>(cp));
    }
    i += n;
  }
  return out;
}

Var text(const char* name, const std::string& s) {
  const auto units = utf16(s);
  if (units.empty()) {
    std::size_t dims[2] = {0, 0};
    return checked(Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UINT16, 2, dims, nullptr, 0), "an empty char array");
  }
  std::size_t dims[2] = {1, units.size()};
  auto* data = const_cast<std::uint16_t*>(units.data());
  return checked(Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UINT16, 2, dims, data, 0), "a char array");
}

Var cells(const char* name, std::vector<Var> items, std::size_t rows, std::size_t columns) {
  std::size_t dims[2] = {rows, columns};
  auto cell = checked(Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0), "a cell array");
  for (std::size_t i = 0; i < items.size(); ++i) Mat_VarSetCell(cell.get(), static_cast<int>(i), items[i].release());
  return cell;
}

Var value_of(const char* name, const json& j);

// The fields of objects `items` under MATLAB names (the header's rule), in
// the order of first appearance; `renamed` when a name differs from its key.
struct Fields {
  std::vector<std::string> keys, names;
  bool renamed = false;
};

Fields fields_of(const std::vector<const json*>& items) {
  Fields f;
  std::set<std::string> seen_keys, taken;
  for (const auto* item : items) {
    for (const auto& [key, value] : item->items()) {
      if (!seen_keys.insert(key).second) continue;
      std::string name = matlab_name(key);
      // Two keys that map to one name: the later gets a number.
      for (int k = 2; taken.count(name); ++k) {
        const auto suffix = fmt::format("_{}", k);
        name = matlab_name(key).substr(0, 63 - suffix.size()) + suffix;
      }
      taken.insert(name);
      f.renamed = f.renamed || name != key;
      f.keys.push_back(key);
      f.names.push_back(std::move(name));
    }
  }
  return f;
}

Var structs(const char* name, const std::vector<const json*>& items) {
  const auto f = fields_of(items);
  std::vector<std::string> names = f.names;
  if (f.renamed) names.emplace_back("json_keys");
  std::vector<const char*> pointers;
  for (const auto& n : names) pointers.push_back(n.c_str());
  std::size_t dims[2] = {1, items.size()};
  auto s = checked(Mat_VarCreateStruct(name, 2, dims, pointers.empty() ? nullptr : pointers.data(),
                                       static_cast<unsigned>(pointers.size())),
                   "a struct");
  for (std::size_t i = 0; i < items.size(); ++i) {
    for (std::size_t k = 0; k < f.keys.size(); ++k) {
      const auto it = items[i]->find(f.keys[k]);
      Var v = it == items[i]->end() ? empty(f.names[k].c_str()) : value_of(f.names[k].c_str(), *it);
      Mat_VarFree(Mat_VarSetStructFieldByName(s.get(), f.names[k].c_str(), i, v.release()));
    }
    if (f.renamed) {
      std::vector<Var> keys;
      for (const auto& key : f.keys) keys.push_back(text(nullptr, key));
      Mat_VarFree(Mat_VarSetStructFieldByName(s.get(), "json_keys", i,
                                              cells("json_keys", std::move(keys), 1, f.keys.size()).release()));
    }
  }
  return s;
}

Var array_of(const char* name, const json& a) {
  if (a.empty()) return empty(name);
  const auto all = [&](auto test) { return std::all_of(a.begin(), a.end(), test); };
  if (all([](const json& x) { return x.is_number() || x.is_null(); })) {
    std::vector<double> v;
    for (const auto& x : a) v.push_back(x.is_null() ? std::numeric_limits<double>::quiet_NaN() : x.get<double>());
    return doubles(name, v, 1, v.size());
  }
  if (all([](const json& x) { return x.is_boolean(); })) {
    std::vector<std::uint8_t> v;
    for (const auto& x : a) v.push_back(x.get<bool>() ? 1 : 0);
    return logicals(name, v);
  }
  const auto row_length = a.front().is_array() ? a.front().size() : 0;
  if (row_length > 0 && all([&](const json& r) {
        return r.is_array() && r.size() == row_length &&
               std::all_of(r.begin(), r.end(), [](const json& x) { return x.is_number() || x.is_null(); });
      })) {
    // MATLAB stores columns first: element (i, k) at i + k * rows.
    const std::size_t rows = a.size();
    std::vector<double> v(rows * row_length);
    for (std::size_t i = 0; i < rows; ++i) {
      for (std::size_t k = 0; k < row_length; ++k) {
        const auto& x = a[i][k];
        v[i + k * rows] = x.is_null() ? std::numeric_limits<double>::quiet_NaN() : x.get<double>();
      }
    }
    return doubles(name, v, rows, row_length);
  }
  if (all([](const json& x) { return x.is_object(); })) {
    std::vector<const json*> items;
    for (const auto& x : a) items.push_back(&x);
    return structs(name, items);
  }
  std::vector<Var> items;
  for (const auto& x : a) items.push_back(value_of(nullptr, x));
  return cells(name, std::move(items), 1, a.size());
}

Var value_of(const char* name, const json& j) {
  switch (j.type()) {
    case json::value_t::object: return structs(name, {&j});
    case json::value_t::array: return array_of(name, j);
    case json::value_t::string: return text(name, j.get<std::string>());
    case json::value_t::boolean: return logicals(name, {static_cast<std::uint8_t>(j.get<bool>() ? 1 : 0)});
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: return doubles(name, {j.get<double>()}, 1, 1);
    default: return empty(name);
  }
}

Var table_of(const MatTable& t, std::size_t rows) {
  std::vector<std::string> names;
  for (const auto& c : t.columns) names.push_back(matlab_name(c.name));
  std::vector<const char*> pointers;
  for (const auto& n : names) pointers.push_back(n.c_str());
  std::size_t dims[2] = {1, 1};
  auto s = checked(Mat_VarCreateStruct(t.name.c_str(), 2, dims, pointers.data(), static_cast<unsigned>(pointers.size())),
                   "a table");
  for (std::size_t k = 0; k < t.columns.size(); ++k) {
    Var column;
    if (const auto* v = std::get_if<std::vector<double>>(&t.columns[k].values)) {
      column = doubles(names[k].c_str(), *v, rows, 1);
    } else {
      std::vector<Var> items;
      for (const auto& x : std::get<std::vector<std::string>>(t.columns[k].values)) items.push_back(text(nullptr, x));
      column = cells(names[k].c_str(), std::move(items), rows, 1);
    }
    Mat_VarFree(Mat_VarSetStructFieldByName(s.get(), names[k].c_str(), 0, column.release()));
  }
  return s;
}

Var units_of(const MatTable& t) {
  json units = json::object();
  for (const auto& c : t.columns) units[c.name] = c.unit;
  return value_of((t.name + "_units").c_str(), units);
}

std::size_t rows_of(const MatTable& t) {
  if (matlab_name(t.name) != t.name) {
    throw std::invalid_argument(fmt::format("MAT table '{}': not a MATLAB name", t.name));
  }
  std::optional<std::size_t> rows;
  for (const auto& c : t.columns) {
    const auto n = std::visit([](const auto& v) { return v.size(); }, c.values);
    if (rows && *rows != n) {
      throw std::invalid_argument(
          fmt::format("MAT table '{}': column '{}' has {} rows where the others have {}", t.name, c.name, n, *rows));
    }
    rows = n;
  }
  return rows.value_or(0);
}

// Bytes the largest variable holds, about: 8 a number, 2 a character.
double largest_variable(const json& document, const std::vector<MatTable>& tables) {
  const std::function<double(const json&)> bytes = [&](const json& j) -> double {
    if (j.is_object() || j.is_array()) {
      double sum = 0.0;
      for (const auto& x : j) sum += bytes(x) + 8.0;
      return sum;
    }
    return j.is_string() ? 2.0 * static_cast<double>(j.get_ref<const std::string&>().size()) : 8.0;
  };
  double most = 0.0;
  if (document.is_object()) {
    for (const auto& x : document) most = std::max(most, bytes(x));
  }
  for (const auto& t : tables) {
    double sum = 0.0;
    for (const auto& c : t.columns) {
      sum += std::visit(
          [](const auto& v) {
            double s = 0.0;
            for (const auto& x : v) {
              if constexpr (std::is_same_v<std::decay_t<decltype(x)>, double>) s += 8.0;
              else s += 2.0 * static_cast<double>(x.size()) + 8.0;
            }
            return s;
          },
          c.values);
    }
    most = std::max(most, sum);
  }
  return most;
}

}  // namespace

std::string matlab_name(const std::string& key) {
  std::string out;
  for (const char c : key) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '_';
  if (out.empty() || !std::isalpha(static_cast<unsigned char>(out.front()))) out.insert(out.begin(), 'x');
  if (out.size() > 63) out.resize(63);
  return out;
}

void write_mat(const std::filesystem::path& path, const nlohmann::json& document, const std::vector<MatTable>& tables,
               MatVersion version) {
  std::vector<std::size_t> rows;
  for (const auto& t : tables) rows.push_back(rows_of(t));
  if (version == MatVersion::v5 && largest_variable(document, tables) > kVersion5Bytes) version = MatVersion::v7_3;
  write_atomically(path, [&](const std::filesystem::path& temporary) {
    std::unique_ptr<mat_t, MatClose> mat(Mat_CreateVer(temporary.c_str(), "pdp results (docs/output.md)",
                                                       version == MatVersion::v5 ? MAT_FT_MAT5 : MAT_FT_MAT73));
    if (!mat) throw OutputError(fmt::format("{}: matio cannot create the file", path.string()));
    const auto write = [&](Var v) {
      if (Mat_VarWrite(mat.get(), v.get(), MAT_COMPRESSION_NONE) != 0) {
        throw OutputError(fmt::format("{}: matio could not write variable '{}'", path.string(), v->name));
      }
    };
    if (document.is_object()) {
      std::vector<const json*> top{&document};
      const auto f = fields_of(top);
      for (std::size_t k = 0; k < f.keys.size(); ++k) write(value_of(f.names[k].c_str(), document.at(f.keys[k])));
    }
    for (std::size_t i = 0; i < tables.size(); ++i) {
      write(table_of(tables[i], rows[i]));
      write(units_of(tables[i]));
    }
  });
}

}  // namespace awcc
