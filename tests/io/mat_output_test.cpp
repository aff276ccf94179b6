// Results as MATLAB variables (awcc/mat_output.hpp): a document of every
// JSON shape written in both versions and read back with matio, each value
// against the mapping of the header; names made MATLAB names; tables with
// their units; a table whose columns differ in length refused.
#include <gtest/gtest.h>
#include <matio.h>

#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "awcc/mat_output.hpp"
#include "test_paths.hpp"

namespace {

using nlohmann::json;

struct Closer {
  void operator()(mat_t* m) const noexcept { Mat_Close(m); }
};
struct Freer {
  void operator()(matvar_t* v) const noexcept { Mat_VarFree(v); }
};
using Var = std::unique_ptr<matvar_t, Freer>;

Var read(const std::filesystem::path& path, const char* name) {
  std::unique_ptr<mat_t, Closer> mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
  EXPECT_TRUE(mat) << path;
  if (!mat) return nullptr;
  return Var(Mat_VarRead(mat.get(), name));
}

std::vector<double> doubles(const matvar_t* v) {
  EXPECT_EQ(v->class_type, MAT_C_DOUBLE);
  const auto* d = static_cast<const double*>(v->data);
  std::size_t n = 1;
  for (int k = 0; k < v->rank; ++k) n *= v->dims[k];
  return {d, d + n};
}

std::string text(const matvar_t* v) {
  EXPECT_EQ(v->class_type, MAT_C_CHAR);
  std::string out;
  const std::size_t n = v->dims[0] * v->dims[1];
  if (v->data_type == MAT_T_UINT16 || v->data_type == MAT_T_UTF16) {
    // UTF-16 to UTF-8 for the BMP: the test's strings need no surrogates.
    const auto* d = static_cast<const std::uint16_t*>(v->data);
    for (std::size_t i = 0; i < n; ++i) {
      const unsigned c = d[i];
      if (c < 0x80) {
        out += static_cast<char>(c);
      } else if (c < 0x800) {
        out += static_cast<char>(0xC0 | (c >> 6));
        out += static_cast<char>(0x80 | (c & 0x3F));
      } else {
        out += static_cast<char>(0xE0 | (c >> 12));
        out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (c & 0x3F));
      }
    }
  } else {
    out.assign(static_cast<const char*>(v->data), n);
  }
  return out;
}

matvar_t* field(const matvar_t* s, const char* name, std::size_t index = 0) {
  auto* f = Mat_VarGetStructFieldByName(const_cast<matvar_t*>(s), name, index);
  EXPECT_NE(f, nullptr) << name;
  return f;
}

const json document = json::parse(R"({
  "file": "dc157_05.dat",
  "note": "u = 2.5 m/s ± 3 %, 20 µs",
  "count": 7,
  "velocity": 2.698,
  "ok": true,
  "nothing": null,
  "ci95": [2.46, 2.99],
  "flags": [true, false, true],
  "missing": [1.5, null],
  "matrix": [[1, 2, 3], [4, 5, 6]],
  "empty": [],
  "mixed": [1, "two", {"three": 3}],
  "quantiles": {"0.025": 2.1, "0.5": 2.4, "0.975": 2.8},
  "profile": [{"position": 0.002, "velocity": 2.8}, {"position": 0.008, "fscc": {"velocity": 2.5}}]
})");

void check_document(const std::filesystem::path& path) {
  EXPECT_EQ(text(read(path, "file").get()), "dc157_05.dat");
  EXPECT_EQ(text(read(path, "note").get()), "u = 2.5 m/s ± 3 %, 20 µs");
  EXPECT_EQ(doubles(read(path, "count").get()), std::vector<double>{7.0});
  EXPECT_EQ(doubles(read(path, "velocity").get()), std::vector<double>{2.698});
  {
    const auto ok = read(path, "ok");
    EXPECT_TRUE(ok->isLogical);
    EXPECT_EQ(static_cast<const std::uint8_t*>(ok->data)[0], 1);
  }
  {
    const auto none = read(path, "nothing");
    EXPECT_EQ(none->dims[0] * none->dims[1], 0u);
  }
  {
    const auto ci = read(path, "ci95");
    EXPECT_EQ(ci->dims[0], 1u);
    EXPECT_EQ(ci->dims[1], 2u);
    EXPECT_EQ(doubles(ci.get()), (std::vector<double>{2.46, 2.99}));
  }
  {
    const auto flags = read(path, "flags");
    ASSERT_TRUE(flags->isLogical);
    const auto* f = static_cast<const std::uint8_t*>(flags->data);
    EXPECT_EQ((std::vector<int>{f[0], f[1], f[2]}), (std::vector<int>{1, 0, 1}));
  }
  {
    const auto m = doubles(read(path, "missing").get());
    EXPECT_EQ(m[0], 1.5);
    EXPECT_TRUE(std::isnan(m[1]));
  }
  {
    // 2 x 3, stored by columns.
    const auto m = read(path, "matrix");
    EXPECT_EQ(m->dims[0], 2u);
    EXPECT_EQ(m->dims[1], 3u);
    EXPECT_EQ(doubles(m.get()), (std::vector<double>{1, 4, 2, 5, 3, 6}));
  }
  EXPECT_EQ(read(path, "empty")->dims[1], 0u);
  {
    const auto c = read(path, "mixed");
    ASSERT_EQ(c->class_type, MAT_C_CELL);
    EXPECT_EQ(doubles(Mat_VarGetCell(c.get(), 0)), std::vector<double>{1.0});
    EXPECT_EQ(text(Mat_VarGetCell(c.get(), 1)), "two");
    EXPECT_EQ(doubles(field(Mat_VarGetCell(c.get(), 2), "three")), std::vector<double>{3.0});
  }
  {
    // Keys that are no MATLAB names: renamed, the originals in json_keys.
    const auto q = read(path, "quantiles");
    ASSERT_EQ(q->class_type, MAT_C_STRUCT);
    EXPECT_EQ(doubles(field(q.get(), "x0_025")), std::vector<double>{2.1});
    EXPECT_EQ(doubles(field(q.get(), "x0_975")), std::vector<double>{2.8});
    const auto* keys = field(q.get(), "json_keys");
    ASSERT_EQ(keys->class_type, MAT_C_CELL);
    EXPECT_EQ(text(Mat_VarGetCell(const_cast<matvar_t*>(keys), 0)), "0.025");
  }
  {
    // Objects in an array: a 1 x 2 struct array of the union of their keys.
    const auto p = read(path, "profile");
    ASSERT_EQ(p->class_type, MAT_C_STRUCT);
    EXPECT_EQ(p->dims[1], 2u);
    EXPECT_EQ(doubles(field(p.get(), "position", 1)), std::vector<double>{0.008});
    EXPECT_EQ(doubles(field(field(p.get(), "fscc", 1), "velocity")), std::vector<double>{2.5});
    EXPECT_EQ(field(p.get(), "fscc", 0)->dims[1], 0u);  // the first row has none: []
  }
}

TEST(MatOutput, EveryJsonShapeReadsBackInBothVersions) {
  for (const auto version : {awcc::MatVersion::v5, awcc::MatVersion::v7_3}) {
    const auto path = pdp_test::test_file(version == awcc::MatVersion::v5 ? "v5.mat" : "v73.mat");
    awcc::write_mat(path, document, {}, version);
    {
      std::unique_ptr<mat_t, Closer> mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
      ASSERT_TRUE(mat);
      EXPECT_EQ(Mat_GetVersion(mat.get()), version == awcc::MatVersion::v5 ? MAT_FT_MAT5 : MAT_FT_MAT73);
    }
    check_document(path);
  }
}

TEST(MatOutput, TablesAreStructsOfColumnsWithTheirUnits) {
  const auto path = pdp_test::test_file("table.mat");
  awcc::MatTable t{"windows", {{"velocity", "m/s", std::vector<double>{2.1, 2.5, 2.9}},
                               {"fate", "", std::vector<std::string>{"accepted", "roc", "accepted"}}}};
  awcc::write_mat(path, json::object(), {t});
  const auto w = read(path, "windows");
  ASSERT_EQ(w->class_type, MAT_C_STRUCT);
  const auto* v = field(w.get(), "velocity");
  EXPECT_EQ(v->dims[0], 3u);  // a column
  EXPECT_EQ(v->dims[1], 1u);
  EXPECT_EQ(doubles(v), (std::vector<double>{2.1, 2.5, 2.9}));
  const auto* fate = field(w.get(), "fate");
  ASSERT_EQ(fate->class_type, MAT_C_CELL);
  EXPECT_EQ(text(Mat_VarGetCell(const_cast<matvar_t*>(fate), 1)), "roc");
  const auto units = read(path, "windows_units");
  EXPECT_EQ(text(field(units.get(), "velocity")), "m/s");
  EXPECT_EQ(text(field(units.get(), "fate")), "");
  // Columns of different lengths: refused, and no file.
  t.columns[1].values = std::vector<std::string>{"accepted"};
  const auto refused = pdp_test::test_file("refused.mat");
  EXPECT_THROW(awcc::write_mat(refused, json::object(), {t}), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(refused));
}

TEST(MatOutput, NamesBecomeMatlabNames) {
  EXPECT_EQ(awcc::matlab_name("velocity_ci95"), "velocity_ci95");
  EXPECT_EQ(awcc::matlab_name("0.025"), "x0_025");
  EXPECT_EQ(awcc::matlab_name("_private"), "x_private");
  EXPECT_EQ(awcc::matlab_name("a-b c"), "a_b_c");
  EXPECT_EQ(awcc::matlab_name(""), "x");
  EXPECT_EQ(awcc::matlab_name(std::string(70, 'a')).size(), 63u);
}

}  // namespace
