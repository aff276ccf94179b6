#include "correction/model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fmt/format.h>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <tuple>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "correction/rows.hpp"
#include "test_paths.hpp"

namespace {

using correction::Features;
using correction::CorrectionModel;

// A small model: truth = measured * (1 + 0.1 * dy/2mm) + noise, Tu truth =
// measured Tu + 0.02.
CorrectionModel small_model(std::uint64_t seed = 3) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  correction::TrainingData v, t;
  v.features = t.features = Features::count;
  CorrectionModel m;
  std::array<double, 7> lo, hi;
  lo.fill(1e300);
  hi.fill(-1e300);
  for (int i = 0; i < 400; ++i) {
    Features f;
    f.velocity = 1.0 + 49.0 * u(g);
    f.turbulence_intensity = 0.35 * u(g);
    f.void_fraction = 0.005 + 0.395 * u(g);
    f.d32 = 0.5e-3 + 19.5e-3 * u(g);
    f.dx = 0.5e-3 + 9.5e-3 * u(g);
    f.dy = 2e-3 * u(g);
    f.np = 5 + std::floor(16 * u(g));
    const auto x = f.vector();
    for (std::size_t j = 0; j < 7; ++j) lo[j] = std::min(lo[j], x[j]), hi[j] = std::max(hi[j], x[j]);
    v.x.insert(v.x.end(), x.begin(), x.end());
    t.x.insert(t.x.end(), x.begin(), x.end());
    const double true_u = f.velocity * (1.0 + 0.1 * f.dy / 2e-3) * (1.0 + 0.01 * (u(g) - 0.5));
    v.y.push_back(correction::to_target(m.velocity_form, true_u, f.velocity));
    t.y.push_back(correction::to_target(m.turbulence_form, f.turbulence_intensity + 0.02, f.turbulence_intensity));
  }
  for (std::size_t j = 0; j < 7; ++j) m.ranges.push_back({Features::names[j], lo[j], hi[j]});
  correction::ForestOptions o;
  o.trees = 50;
  o.seed = seed;
  m.velocity = correction::QuantileForest::train(v, o);
  m.turbulence_intensity = correction::QuantileForest::train(t, o);
  m.provenance = "test model";
  return m;
}

Features inside() {
  Features f;
  f.velocity = 10.0;
  f.turbulence_intensity = 0.2;
  f.void_fraction = 0.2;
  f.d32 = 5e-3;
  f.dx = 5e-3;
  f.dy = 1e-3;
  f.np = 10;
  f.windows_accepted = 500;
  return f;
}

// A 45 s, 20 kHz row at 3 m/s with 30 of 300 windows: what labs record.
Features lab_row() {
  Features f = inside();
  f.velocity = 3.0;
  f.fs = 20e3;
  f.duration = 45;
  f.windows_accepted = 30;
  f.windows_total = 300;
  f.time_scale_ratio = 2.0;
  return f;
}

// A model of 300 runs drawn by `draw` on the feature set `set`: its ranges
// those of the draws, its velocity forest learning `velocity_target(f)`
// (ratio form), its Tu forest 0.01 (difference form); 5 trees, min windows 10.
double uniform(std::mt19937_64& g) { return std::uniform_real_distribution<double>(0.0, 1.0)(g); }

CorrectionModel model_of(const std::string& set, std::uint64_t seed,
                         const std::function<void(Features&, std::mt19937_64&)>& draw,
                         const std::function<double(const Features&)>& velocity_target) {
  std::mt19937_64 g(seed);
  const auto names = correction::feature_set_names(set);
  correction::TrainingData v, t;
  v.features = t.features = static_cast<int>(names.size());
  CorrectionModel m;
  for (const auto& n : names) m.ranges.push_back({n, 1e300, -1e300});
  for (int i = 0; i < 300; ++i) {
    Features f = inside();
    draw(f, g);
    std::vector<double> x;
    for (std::size_t j = 0; j < names.size(); ++j) {
      x.push_back(*f.value(names[j]));
      m.ranges[j].min = std::min(m.ranges[j].min, x.back());
      m.ranges[j].max = std::max(m.ranges[j].max, x.back());
    }
    v.x.insert(v.x.end(), x.begin(), x.end());
    t.x.insert(t.x.end(), x.begin(), x.end());
    v.y.push_back(velocity_target(f));
    t.y.push_back(0.01);
  }
  correction::ForestOptions o;
  o.trees = 5;
  m.velocity = correction::QuantileForest::train(v, o);
  m.turbulence_intensity = correction::QuantileForest::train(t, o);
  m.min_windows = 10;
  return m;
}

TEST(Correction, Crc32MatchesTheStandardCheckValue) {
  const char* text = "123456789";
  EXPECT_EQ(correction::crc32(reinterpret_cast<const std::uint8_t*>(text), 9), 0xCBF43926u);
}

TEST(Correction, Crc32EqualsTheBitwiseDefinitionAtEveryLengthAndAlignment) {
  // The reflected polynomial 0xEDB88320 one bit at a time, against the
  // model file's checksum (zlib's, whose fast paths work on blocks and
  // tails): every length 0-300 and long buffers, from odd offsets.
  auto bitwise = [](const std::uint8_t* p, std::size_t n) {
    std::uint32_t c = 0xffffffffu;
    for (std::size_t i = 0; i < n; ++i) {
      c ^= p[i];
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
    }
    return c ^ 0xffffffffu;
  };
  std::mt19937 g(1);
  std::vector<std::uint8_t> bytes(5000);
  for (auto& b : bytes) b = static_cast<std::uint8_t>(g());
  for (std::size_t offset : {0u, 1u, 3u, 7u}) {
    for (std::size_t n = 0; n <= 300; ++n)
      ASSERT_EQ(correction::crc32(bytes.data() + offset, n), bitwise(bytes.data() + offset, n)) << n << " " << offset;
    for (std::size_t n : {1000u, 4093u, 4096u, 4992u})
      ASSERT_EQ(correction::crc32(bytes.data() + offset, n), bitwise(bytes.data() + offset, n)) << n << " " << offset;
  }
}

TEST(Correction, RoundTripGivesTheSameBytesAndPredictions) {
  const auto m = small_model();
  const auto bytes = m.serialise();
  const auto back = CorrectionModel::parse(bytes, "mem");
  EXPECT_EQ(back.serialise(), bytes);
  EXPECT_EQ(back.provenance, "test model");
  const auto a = m.correct(inside()), b = back.correct(inside());
  ASSERT_TRUE(a.corrected()) << a.message;
  ASSERT_TRUE(b.corrected()) << b.message;
  EXPECT_EQ(a.velocity->quantiles, b.velocity->quantiles);
  EXPECT_EQ(a.turbulence_intensity->quantiles, b.turbulence_intensity->quantiles);
  // The learnt factor: truth ~ measured * 1.05 at dy = 1 mm (within the leaf's spread).
  EXPECT_NEAR(a.velocity->median() / 10.0, 1.05, 0.03);
  EXPECT_NEAR(a.turbulence_intensity->median(), 0.22, 1e-12);
}

// More than 65,536 training rows: held rows take 4 bytes on file.
TEST(Correction, LargeTrainingSetsRoundTrip) {
  auto m = small_model();
  correction::TrainingData big;
  big.features = Features::count;
  std::mt19937_64 g(2);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 70000; ++i) {
    for (int j = 0; j < big.features; ++j) big.x.push_back(u(g));
    big.y.push_back(u(g));
  }
  correction::ForestOptions o;
  o.trees = 2;
  o.min_leaf = 50;
  m.velocity = correction::QuantileForest::train(big, o);
  const auto bytes = m.serialise();
  const auto back = CorrectionModel::parse(bytes, "big");
  EXPECT_EQ(back.velocity.trees()[1].leaf_rows, m.velocity.trees()[1].leaf_rows);
  EXPECT_EQ(back.serialise(), bytes);
  std::uint32_t largest = 0;
  const auto back_trees = back.velocity.trees();
  for (auto r : back_trees[0].leaf_rows) largest = std::max(largest, r);
  EXPECT_GT(largest, 65535u);
}

TEST(Correction, FileIsLittleEndianWhateverTheMachine) {
  const auto bytes = small_model().serialise();
  ASSERT_GT(bytes.size(), 24u);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 8), "pdp-qrf\n");
  // Format version 7 as u32 little-endian.
  EXPECT_EQ(bytes[8], 7);
  EXPECT_EQ(bytes[9], 0);
  EXPECT_EQ(bytes[10], 0);
  EXPECT_EQ(bytes[11], 0);
  // Payload length, u64 little-endian, agrees with the file size.
  std::uint64_t length = 0;
  for (int i = 0; i < 8; ++i) length |= static_cast<std::uint64_t>(bytes[12 + static_cast<std::size_t>(i)]) << (8 * i);
  EXPECT_EQ(length + 8 + 4 + 8 + 4, bytes.size());
  // Provenance text: u32 length then the bytes.
  EXPECT_EQ(bytes[20], 10);
  EXPECT_EQ(std::string(bytes.begin() + 24, bytes.begin() + 34), "test model");
}

TEST(Correction, DamagedForeignAndNewerFilesAreRefused) {
  const auto bytes = small_model().serialise();
  auto message = [](const std::vector<std::uint8_t>& b) {
    try {
      (void)CorrectionModel::parse(b, "m.qrf");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  auto flipped = bytes;
  flipped[flipped.size() / 2] ^= 0x10;
  EXPECT_NE(message(flipped).find("checksum"), std::string::npos) << message(flipped);
  auto truncated = bytes;
  truncated.resize(bytes.size() - 100);
  EXPECT_NE(message(truncated).find("m.qrf: damaged"), std::string::npos) << message(truncated);
  const std::string text = "velocity,turbulence_intensity\n1,2\n";
  EXPECT_NE(message({text.begin(), text.end()}).find("not a pdp model file"), std::string::npos);
  auto newer = bytes;
  newer[8] = 8;
  EXPECT_NE(message(newer).find("version 8"), std::string::npos) << message(newer);
  // A structural fault with a valid checksum: the reader checks the trees too.
  auto forged = bytes;
  // The first tree's root node follows the velocity targets; find it by
  // serialising with a recognisable threshold instead of guessing offsets:
  // rewrite the first node's left child to 0 (a cycle) and fix the CRC.
  auto m = small_model();
  auto trees = m.velocity.trees();
  trees[0].nodes[0].left = 0;
  // assemble refuses it directly...
  EXPECT_THROW((void)correction::QuantileForest::assemble(7, m.velocity.targets(), trees), std::invalid_argument);
  // ...and a file carrying it is refused as damaged. Build the file bytes by
  // patching the serialised root (same size) and recomputing the checksum.
  const auto good = m.serialise();
  // A split node on file (format 3): f64 threshold, u32 feature << 24 | left child.
  std::vector<std::uint8_t> node(12);
  const auto velocity_trees = m.velocity.trees();
  const auto& root = velocity_trees[0].nodes[0];
  std::uint64_t bits;
  std::memcpy(&bits, &root.threshold, 8);
  for (int i = 0; i < 8; ++i) node[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(bits >> (8 * i));
  const std::uint32_t info = static_cast<std::uint32_t>(root.feature) << 24 | root.left;
  for (int i = 0; i < 4; ++i) node[8 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(info >> (8 * i));
  const auto at = std::search(good.begin(), good.end(), node.begin(), node.end());
  ASSERT_NE(at, good.end());
  forged = good;
  const auto offset = static_cast<std::size_t>(at - good.begin());
  // Left child 0: a cycle back to the root.
  for (int i = 0; i < 3; ++i) forged[offset + 8 + static_cast<std::size_t>(i)] = 0;
  const auto crc = correction::crc32(forged.data(), forged.size() - 4);
  for (int i = 0; i < 4; ++i) forged[forged.size() - 4 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(crc >> (8 * i));
  EXPECT_NE(message(forged).find("malformed"), std::string::npos) << message(forged);
}

TEST(Correction, LoadNamesTheFileAndSaveIsAtomic) {
  const auto dir = pdp_test::temp_dir() / "correction";
  std::filesystem::create_directories(dir);
  const auto path = dir / "m.qrf";
  small_model().save(path);
  EXPECT_NO_THROW((void)CorrectionModel::load(path));
  EXPECT_FALSE(std::filesystem::exists(dir / "m.qrf.tmp"));
  try {
    (void)CorrectionModel::load(dir / "missing.qrf");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.qrf"), std::string::npos);
  }
}

TEST(Correction, RowsOutsideTheTrainingDataAreFlaggedNotCorrected) {
  const auto m = small_model();
  auto f = inside();
  f.void_fraction = 0.9;
  auto c = m.correct(f);
  EXPECT_EQ(c.status, correction::CorrectionStatus::outside_training_range);
  EXPECT_NE(c.message.find("void_fraction = 0.9"), std::string::npos) << c.message;
  EXPECT_FALSE(c.velocity.has_value());
  f = inside();
  f.windows_accepted = 99;
  c = m.correct(f);
  EXPECT_EQ(c.status, correction::CorrectionStatus::too_few_windows);
  EXPECT_NE(c.message.find("99 accepted windows"), std::string::npos) << c.message;
  // Within the margin below the smallest and above the largest u: in range;
  // beyond it: out (u spans 1-50 m/s: logarithmic below, linear above).
  f = inside();
  const auto& u = m.ranges[0];
  const auto accepted = correction::accepted_range(u, m.range_margin);
  ASSERT_LT(accepted.min, u.min);
  ASSERT_GT(accepted.max, u.max);
  f.velocity = u.min - 0.5 * (u.min - accepted.min);
  EXPECT_TRUE(m.correct(f).corrected());
  f.velocity = u.min - 1.5 * (u.min - accepted.min);
  EXPECT_FALSE(m.correct(f).corrected());
  f.velocity = u.max + 0.5 * (accepted.max - u.max);
  EXPECT_TRUE(m.correct(f).corrected());
  f.velocity = u.max + 1.5 * (accepted.max - u.max);
  EXPECT_FALSE(m.correct(f).corrected());
  f = inside();
  f.velocity = std::nan("");
  EXPECT_FALSE(m.correct(f).corrected());
}

TEST(Correction, AFeatureOnALogarithmicScaleGetsALogarithmicMarginAtItsLowEnd) {
  // c drawn over 0.005-0.6: 1 % of the span (0.00595) would take every
  // c > -0.00095, the whole lower decade; the logarithmic margin takes
  // c >= 0.005 / 120^0.01 = 0.0047663 (1 % of ln 120 below ln 0.005).
  const auto c = correction::accepted_range({"void_fraction", 0.005, 0.6}, 0.01);
  EXPECT_NEAR(c.min, 0.005 / std::pow(120.0, 0.01), 1e-15);
  EXPECT_NEAR(c.min, 0.0047663, 1e-7);
  // At the top, linear (0.60595; the logarithmic one would be 0.6294).
  EXPECT_DOUBLE_EQ(c.max, 0.6 + 0.01 * 0.595);
  // Features whose 0 is a value stay linear at both ends, even when their
  // training minimum is a tiny positive number: an inline probe (dy = 0)
  // and still water in Tu must stay inside a model trained from 0.0005 mm.
  const auto dy = correction::accepted_range({"dy", 4.876e-7, 2e-3}, 0.01);
  EXPECT_LT(dy.min, 0.0);
  EXPECT_DOUBLE_EQ(dy.min, 4.876e-7 - 0.01 * (2e-3 - 4.876e-7));
  const auto tu = correction::accepted_range({"turbulence_intensity", 1e-4, 0.45}, 0.01);
  EXPECT_LT(tu.min, 0.0);
  const auto np = correction::accepted_range({"np", 3.0, 30.0}, 0.01);
  EXPECT_DOUBLE_EQ(np.min, 3.0 - 0.27);
  // Every feature the log scale names, from u to FSCC's lag.
  for (const char* name : correction::Features::log_scale_names) {
    const auto r = correction::accepted_range({name, 2.0, 200.0}, 0.01);
    EXPECT_NEAR(r.min, 2.0 / std::pow(100.0, 0.01), 1e-12) << name;
    EXPECT_DOUBLE_EQ(r.max, 200.0 + 1.98) << name;
  }

  // Through the model: the real profile's lowest row (c = 0.0037) against
  // a model trained from c = 0.005 is refused, naming void_fraction; inside
  // the logarithmic margin it is corrected.
  const auto m = model_of("measured", 11,
                          [](Features& f, std::mt19937_64& g) { f.void_fraction = 0.005 * std::pow(120.0, uniform(g)); },
                          [](const Features&) { return 1.0; });
  const auto& range = m.ranges[2];
  ASSERT_EQ(range.name, "void_fraction");
  auto f = inside();
  f.void_fraction = 0.0037 / 0.005 * range.min;
  const auto refused = m.correct(f);
  EXPECT_EQ(refused.status, correction::CorrectionStatus::outside_training_range);
  EXPECT_NE(refused.message.find("void_fraction"), std::string::npos) << refused.message;
  f.void_fraction = range.min * std::pow(range.max / range.min, -0.005);
  EXPECT_TRUE(m.correct(f).corrected()) << m.correct(f).why_not();
}

TEST(Correction, TargetFormsInvert) {
  for (auto form : {correction::TargetForm::value, correction::TargetForm::ratio, correction::TargetForm::difference}) {
    const double t = correction::to_target(form, 7.5, 6.0);
    EXPECT_DOUBLE_EQ(correction::from_target(form, t, 6.0), 7.5) << correction::to_string(form);
  }
}

TEST(Correction, JsonHasTheDocumentedKeys) {
  const auto c = small_model().correct(inside());
  const auto j = correction::to_json(c);
  EXPECT_TRUE(j["in_range"].get<bool>());
  EXPECT_TRUE(j["reason"].is_null());
  for (const char* q : {"velocity", "turbulence_intensity"}) {
    const auto& quantiles = j[q]["quantiles"];
    // pdp-uq's nine levels.
    ASSERT_EQ(quantiles.size(), 9u);
    for (const char* key : {"0.025", "0.05", "0.1", "0.25", "0.5", "0.75", "0.9", "0.95", "0.975"}) {
      ASSERT_TRUE(quantiles.contains(key)) << key;
    }
    EXPECT_EQ(j[q]["median"], quantiles["0.5"]);
  }
}

// The correction's profile CSV cells equal its JSON at each declared pointer
// (the report's table reads the JSON through them), corrected or not.
TEST(Correction, CsvCellsEqualTheJsonAtTheirPointers) {
  const auto m = small_model();
  auto outside = inside();
  outside.void_fraction = 0.9;
  // An untrusted row with notes: quantiles without a corrected median, a list joined by "; ".
  auto untrusted = m.correct(inside());
  untrusted.status = correction::CorrectionStatus::untrusted;
  untrusted.message = "outside the envelope: a test";
  untrusted.notes = {"duration 600 s is beyond the training range (20-300 s): corrected as 300 s", "a second, note"};
  for (const auto& c : {m.correct(inside()), m.correct(outside), untrusted}) {
    const nlohmann::json row = {{"correction", correction::to_json(c)}};
    const auto cells = awcc::split_cells(correction::correction_csv_cells(c));
    const auto columns = correction::correction_csv_columns();
    ASSERT_EQ(cells.size(), columns.size());
    EXPECT_EQ(awcc::split_cells(correction::correction_csv_header()).size(), columns.size());
    for (std::size_t k = 0; k < columns.size(); ++k) {
      const nlohmann::json::json_pointer p{std::string(columns[k].json_pointer)};
      const auto value = row.contains(p) ? row.at(p) : nlohmann::json(nullptr);
      std::string expected;
      if (value.is_boolean()) expected = value.get<bool>() ? "1" : "0";
      else if (value.is_number()) expected = fmt::format("{:.10g}", value.get<double>());
      else if (value.is_string()) expected = value.get<std::string>();
      else if (value.is_array())
        for (const auto& n : value) expected += (expected.empty() ? "" : "; ") + n.get<std::string>();
      EXPECT_EQ(cells[k], expected) << columns[k].name << " (" << c.message << ")";
    }
  }
}

TEST(Correction, MeasurementOfAProcessedRecording) {
  awcc::ProcessResult r;
  auto m = correction::measurement_of(r);
  EXPECT_EQ(m.status, correction::CorrectionStatus::awcc_not_run);
  r.dx = 5e-3;
  r.dy = 1e-3;
  r.tips.resize(2);
  r.tips[0].phase.void_fraction = 0.2;
  r.tips[0].phase.bubble_count_rate = 600.0;
  r.awcc = awcc::AwccResult{};
  r.awcc->status = awcc::AwccStatus::too_few_windows;
  r.awcc->message = "1 of 9 windows accepted";
  m = correction::measurement_of(r);
  EXPECT_EQ(m.status, correction::CorrectionStatus::no_awcc_velocity);
  EXPECT_NE(m.message.find("1 of 9 windows"), std::string::npos);
  r.awcc->status = awcc::AwccStatus::ok;
  r.awcc->quality = awcc::AwccQuality::low;
  r.awcc->quality_reason = "42 accepted windows";
  // Low quality is AWCC's flag, not a refusal: the model's least windows decide.
  EXPECT_EQ(correction::measurement_of(r).status, correction::CorrectionStatus::corrected);
  r.awcc->quality = awcc::AwccQuality::ok;
  r.awcc->velocity = 10.0;
  r.awcc->turbulence_intensity = 0.25;
  r.awcc->np = 12;
  r.awcc->windows_accepted = 321;
  m = correction::measurement_of(r);
  ASSERT_EQ(m.status, correction::CorrectionStatus::corrected);
  const auto f = correction::make_features(m.measurement);
  ASSERT_TRUE(f.ok());
  EXPECT_DOUBLE_EQ(f.features.d32, 1.5 * 10.0 * 0.2 / 600.0);
  EXPECT_EQ(f.features.np, 12.0);
  EXPECT_EQ(f.features.windows_accepted, 321);
  EXPECT_EQ(f.features.dy, 1e-3);
  // The time-scale ratio is AWCC's (AwccResult::time_scale_ratio, set by
  // AWCC and tested there): not known when AWCC does not give it.
  EXPECT_FALSE(m.measurement.time_scale_ratio);
  EXPECT_FALSE(f.features.value("time_scale_ratio"));
  r.awcc->time_scale_ratio = 3.25;
  m = correction::measurement_of(r);
  ASSERT_TRUE(m.measurement.time_scale_ratio);
  EXPECT_EQ(*correction::make_features(m.measurement).features.value("time_scale_ratio"), 3.25);
  // AWCC's edge and spread rules (awcc.hpp): a Tu not measured, or windows
  // piled up at an end of the velocity range, are refused with AWCC's
  // reason; a study still reads the raw values. 16 of 321 at the ends is 5.0 %,
  // not above the share; 17 is.
  r.awcc->quality_reason = "every one of the windows peaks at one lag";
  r.awcc->turbulence_measured = false;
  m = correction::measurement_of(r);
  EXPECT_EQ(m.status, correction::CorrectionStatus::awcc_not_measured);
  EXPECT_NE(m.message.find("every one of the windows"), std::string::npos) << m.message;
  EXPECT_EQ(m.measurement.velocity, 10.0);
  r.awcc->turbulence_measured = true;
  r.awcc->windows_at_least_lag = 10;
  r.awcc->windows_at_greatest_lag = 6;
  EXPECT_EQ(correction::measurement_of(r).status, correction::CorrectionStatus::corrected);
  r.awcc->windows_at_greatest_lag = 7;
  EXPECT_EQ(correction::measurement_of(r).status, correction::CorrectionStatus::awcc_not_measured);
}

// The feature contract refuses what has no features, each with its status.
TEST(Correction, FeaturesNeedAPositiveVelocityAndBubbles) {
  correction::Measurement m;
  EXPECT_EQ(correction::make_features(m).status, correction::CorrectionStatus::no_awcc_velocity);
  m.velocity = -0.5;
  m.turbulence_intensity = 0.1;
  m.bubble_count_rate = 10.0;
  EXPECT_EQ(correction::make_features(m).status, correction::CorrectionStatus::no_awcc_velocity);
  m.velocity = 0.5;
  m.bubble_count_rate = 0.0;
  EXPECT_EQ(correction::make_features(m).status, correction::CorrectionStatus::no_bubbles);
  m.bubble_count_rate = 10.0;
  EXPECT_TRUE(correction::make_features(m).ok());
}

// A model applies to results processed as its training data; every
// difference is named.
TEST(Correction, ProcessingMismatchNamesEachDifference) {
  correction::Processing model, results;
  EXPECT_EQ(correction::processing_mismatch(model, results), "");
  results.filter_a = 0.3;
  results.roc = false;
  const auto why = correction::processing_mismatch(model, results);
  EXPECT_NE(why.find("filter A: model 0.4, results 0.3"), std::string::npos) << why;
  EXPECT_NE(why.find("robust outlier cutoff: model on, results off"), std::string::npos) << why;
  results = model;
  results.signal = awcc::CorrelationSignal::raw;
  EXPECT_NE(correction::processing_mismatch(model, results).find("correlated signal"), std::string::npos);
}

// The processing survives the file; version 1 files read as the default.
TEST(Correction, ModelFileKeepsTheProcessing) {
  auto m = small_model();
  m.processing.filter_a = 0.25;
  m.processing.weighting = awcc::Weighting::none;
  m.processing.subsample = awcc::Subsample::parabolic;
  const auto back = CorrectionModel::parse(m.serialise(), "m.qrf");
  EXPECT_TRUE(back.processing == m.processing);
  EXPECT_NE(back.mismatch(correction::Processing{}), "");
  const auto shipped = std::filesystem::path(PDP_SOURCE_DIR) / "samples" / "model" / "awcc-60s-500kHz.qrf";
  const auto v1 = CorrectionModel::load(shipped);
  EXPECT_TRUE(v1.processing == correction::Processing{});
}

// An extended model over u 1-50 m/s, fs 10 kHz-1 MHz, 20-300 s and 10-1010
// windows, its velocity target rising with fs.
CorrectionModel extended_model() {
  return model_of("extended", 9, [](Features& f, std::mt19937_64& g) {
    f.velocity = 1 + 49 * uniform(g);
    f.fs = 1e4 + 1e6 * uniform(g);
    f.duration = 20 + 280 * uniform(g);
    f.windows_accepted = 10 + static_cast<std::int64_t>(1000 * uniform(g));
  }, [](const Features& f) { return 1.0 + 1e-7 * f.fs; });
}

TEST(Correction, ExtendedModelsNeedTheRecordsFeaturesAndRoundTrip) {
  // A model whose ranges are the extended set: a row without fs is not
  // corrected and says which feature is missing; with it, it is corrected
  // exactly as the forests say; the file reads back bit for bit, as version 3.
  const auto names = correction::feature_set_names("extended");
  ASSERT_EQ(names.size(), 10u);
  auto m = extended_model();
  Features f = inside();
  const auto missing = m.correct(f);
  EXPECT_EQ(missing.status, correction::CorrectionStatus::missing_feature);
  EXPECT_NE(missing.message.find("fs"), std::string::npos);
  f.fs = 5e5;
  f.duration = 100;
  const auto c = m.correct(f);
  ASSERT_TRUE(c.corrected()) << c.message;
  std::vector<double> x;
  for (const auto& n : names) x.push_back(*f.value(n));
  const auto q = m.velocity.quantiles(x, correction::correction_levels);
  EXPECT_DOUBLE_EQ(c.velocity->median(), correction::from_target(m.velocity_form, q[correction::median_level], f.velocity));
  const auto bytes = m.serialise();
  std::uint32_t version = 0;
  std::memcpy(&version, bytes.data() + 8, 4);
  EXPECT_EQ(version, 7u);
  EXPECT_EQ(CorrectionModel::parse(bytes, "x.qrf").serialise(), bytes);
  // The data yield: accepted over formed windows, when both are known.
  Features y = inside();
  y.windows_accepted = 30;
  EXPECT_FALSE(y.value("data_yield"));
  y.windows_total = 120;
  EXPECT_DOUBLE_EQ(*y.value("data_yield"), 0.25);
  EXPECT_EQ(correction::feature_set_names("extended-yield").back(), "data_yield");
  // The lag in samples: dx fs / u (5 mm at 500 kHz and 2.5 m/s: 1000
  // samples), unknown without the rate, after the record's features and
  // before the weighting feature; not a set of the measured features alone
  // (no rate) nor of FSCC's.
  Features lag = inside();
  lag.dx = 0.005;
  lag.velocity = 2.5;
  lag.fs = 500e3;
  EXPECT_DOUBLE_EQ(*lag.value("lag_samples"), 1000.0);
  lag.fs = 0.0;
  EXPECT_FALSE(lag.value("lag_samples"));
  const auto lag_set = correction::feature_set_names("extended-yield+lag+weighting");
  ASSERT_EQ(lag_set.size(), 12u);
  EXPECT_EQ(lag_set[9], "data_yield");
  EXPECT_EQ(lag_set[10], "lag_samples");
  EXPECT_EQ(lag_set[11], "awcc_unweighted");
  EXPECT_EQ(correction::feature_set_of(lag_set), "extended-yield+lag+weighting");
  EXPECT_EQ(correction::feature_set_of(correction::feature_set_names("extended+lag")), "extended+lag");
  EXPECT_THROW(correction::feature_set_names("measured+lag"), std::invalid_argument);
  EXPECT_THROW(correction::feature_set_names("fscc+lag"), std::invalid_argument);
  EXPECT_TRUE(Features::on_log_scale("lag_samples"));
  EXPECT_EQ(correction::feature_value_text("lag_samples", 12.5), "lag_samples = 12.5 samples");
  // The time-scale ratio: after the lag, before the weighting; unknown until
  // a measurement gives it; extended sets only, each suffix once and in order.
  Features scale = inside();
  EXPECT_FALSE(scale.value("time_scale_ratio"));
  scale.time_scale_ratio = 2.5;
  EXPECT_DOUBLE_EQ(*scale.value("time_scale_ratio"), 2.5);
  const auto scale_set = correction::feature_set_names("extended-yield+lag+scale+weighting");
  ASSERT_EQ(scale_set.size(), 13u);
  EXPECT_EQ(scale_set[10], "lag_samples");
  EXPECT_EQ(scale_set[11], "time_scale_ratio");
  EXPECT_EQ(scale_set[12], "awcc_unweighted");
  for (const char* set : {"extended+scale", "extended-yield+scale+weighting", "extended+lag+scale",
                          "extended-yield+lag+scale+weighting"}) {
    EXPECT_EQ(correction::feature_set_of(correction::feature_set_names(set)), set);
  }
  for (const char* set : {"measured+scale", "extended+scale+lag", "extended+lag+lag", "extended+scales",
                          "extended+weighting+scale", "extended+", "fscc+scale"}) {
    EXPECT_THROW(correction::feature_set_names(set), std::invalid_argument) << set;
  }
  EXPECT_TRUE(Features::on_log_scale("time_scale_ratio"));
  EXPECT_EQ(correction::feature_value_text("time_scale_ratio", 20.0), "time_scale_ratio = 20");
  // The size ratio d32 / dx: after the time scale, before the weighting;
  // known whenever d32 and dx are.
  Features size = inside();
  size.d32 = 6e-3;
  size.dx = 4e-3;
  EXPECT_DOUBLE_EQ(*size.value("size_ratio"), 1.5);
  size.d32 = 0.0;
  EXPECT_FALSE(size.value("size_ratio"));
  const auto size_set = correction::feature_set_names("extended-yield+lag+scale+size+weighting");
  ASSERT_EQ(size_set.size(), 14u);
  EXPECT_EQ(size_set[12], "size_ratio");
  EXPECT_EQ(size_set[13], "awcc_unweighted");
  for (const char* set : {"extended+size", "extended-yield+lag+size+weighting", "extended-yield+lag+scale+size+weighting"})
    EXPECT_EQ(correction::feature_set_of(correction::feature_set_names(set)), set);
  for (const char* set : {"measured+size", "extended+size+scale", "extended+weighting+size"})
    EXPECT_THROW(correction::feature_set_names(set), std::invalid_argument) << set;
  EXPECT_TRUE(Features::on_log_scale("size_ratio"));
  // FSCC beside AWCC: its velocity over AWCC's and its R12max, after the
  // size ratio and before the weighting; unknown without an FSCC velocity.
  Features fscc = inside();
  fscc.velocity = 4.0;
  fscc.fscc_velocity = 3.8;
  fscc.r12_max = 0.42;
  EXPECT_DOUBLE_EQ(*fscc.value("fscc_awcc_ratio"), 0.95);
  EXPECT_DOUBLE_EQ(*fscc.value("r12_max"), 0.42);
  fscc.fscc_velocity = 0.0;
  EXPECT_FALSE(fscc.value("fscc_awcc_ratio"));
  EXPECT_FALSE(fscc.value("r12_max"));
  const auto fscc_set = correction::feature_set_names("extended-yield+lag+scale+fscc+weighting");
  ASSERT_EQ(fscc_set.size(), 15u);
  EXPECT_EQ(fscc_set[11], "time_scale_ratio");
  EXPECT_EQ(fscc_set[12], "fscc_awcc_ratio");
  EXPECT_EQ(fscc_set[13], "r12_max");
  EXPECT_EQ(fscc_set[14], "awcc_unweighted");
  for (const char* set : {"extended+fscc", "extended-yield+lag+scale+fscc+weighting",
                          "extended-yield+lag+scale+size+fscc+weighting"})
    EXPECT_EQ(correction::feature_set_of(correction::feature_set_names(set)), set);
  for (const char* set : {"measured+fscc", "extended+fscc+size", "extended+weighting+fscc", "extended+fscc+fscc"})
    EXPECT_THROW(correction::feature_set_names(set), std::invalid_argument) << set;
  // A ratio near 1 is not drawn over decades: its range margin is linear.
  EXPECT_FALSE(Features::on_log_scale("fscc_awcc_ratio"));
  // Chanson's Tu after FSCC's two: a number, 0 where undefined, wherever
  // FSCC gave a velocity and the source stated it; unknown otherwise.
  Features chanson = inside();
  chanson.fscc_velocity = 3.8;
  chanson.tu_chanson = 0.0;
  EXPECT_EQ(chanson.value("fscc_tu_chanson"), 0.0);
  chanson.tu_chanson = 0.31;
  EXPECT_EQ(chanson.value("fscc_tu_chanson"), 0.31);
  chanson.tu_chanson.reset();
  EXPECT_FALSE(chanson.value("fscc_tu_chanson"));
  chanson.tu_chanson = 0.31;
  chanson.fscc_velocity = 0.0;
  EXPECT_FALSE(chanson.value("fscc_tu_chanson"));
  const auto chanson_set = correction::feature_set_names("extended-yield+lag+scale+fscc+chanson+weighting");
  ASSERT_EQ(chanson_set.size(), 16u);
  EXPECT_EQ(chanson_set[13], "r12_max");
  EXPECT_EQ(chanson_set[14], "fscc_tu_chanson");
  EXPECT_EQ(chanson_set[15], "awcc_unweighted");
  for (const char* set : {"extended+chanson", "extended-yield+lag+scale+fscc+chanson+weighting"})
    EXPECT_EQ(correction::feature_set_of(correction::feature_set_names(set)), set);
  for (const char* set : {"measured+chanson", "extended+chanson+fscc", "extended+weighting+chanson"})
    EXPECT_THROW(correction::feature_set_names(set), std::invalid_argument) << set;
  EXPECT_FALSE(Features::on_log_scale("fscc_tu_chanson"));  // 0 is a value it takes
  // From a result: FSCC's Chanson Tu, or 0 where FSCC left it undefined.
  awcc::ProcessResult processed;
  processed.fscc.emplace();
  processed.fscc->status = awcc::FsccStatus::ok;
  processed.fscc->velocity = 3.8;
  EXPECT_EQ(correction::measurement_of(processed).measurement.tu_chanson, 0.0);
  processed.fscc->turbulence_intensity_chanson = 0.27;
  EXPECT_EQ(correction::measurement_of(processed).measurement.tu_chanson, 0.27);
  correction::Measurement stated;
  stated.velocity = 3.0;
  stated.turbulence_intensity = 0.2;
  stated.void_fraction = 0.1;
  stated.bubble_count_rate = 100.0;
  stated.time_scale_ratio = 7.5;
  EXPECT_EQ(*correction::make_features(stated).features.value("time_scale_ratio"), 7.5);
  // The unknown-record values are not features.
  Features none;
  EXPECT_FALSE(none.value("fs"));
  EXPECT_FALSE(none.value("windows_accepted"));
  EXPECT_FALSE(none.value("colour"));
}

// A reduced model (the measured features alone) over u 1-50 m/s.
CorrectionModel reduced_model() {
  return model_of(
      "measured", 10, [](Features& f, std::mt19937_64& g) { f.velocity = 1 + 49 * uniform(g); },
      [](const Features& f) { return 1.0 + 0.001 * f.velocity; });
}

TEST(Correction, RowsWithoutTheRecordsFeaturesGoToTheReducedModel) {
  // An extended model with a reduced one (issue 33, peers' rows): a row that
  // states fs, duration and windows is the extended model's; a row without
  // any of them is the reduced model's, exactly as that model corrects it
  // alone, its forest named and the missing features said; the file holds
  // both and reads back bit for bit; a reduced model that is not of the
  // measured features alone is refused as damaged.
  auto m = extended_model();
  const auto reduced = std::make_shared<const CorrectionModel>(reduced_model());
  m.reduced = reduced;
  Features full = inside();
  full.fs = 5e5;
  full.duration = 100;
  const auto extended = m.correct(full);
  ASSERT_TRUE(extended.corrected()) << extended.message;
  EXPECT_EQ(extended.forest, "awcc");
  for (auto strip : {+[](Features& f) { f.fs = 0; }, +[](Features& f) { f.duration = 0; },
                     +[](Features& f) { f.windows_accepted = -1; }}) {
    Features peer = full;
    strip(peer);
    const auto c = m.correct(peer);
    ASSERT_TRUE(c.corrected()) << c.message;
    EXPECT_EQ(c.forest, "awcc-reduced");
    const auto alone = reduced->correct(peer);
    ASSERT_TRUE(alone.corrected());
    EXPECT_EQ(c.velocity->quantiles, alone.velocity->quantiles);
    EXPECT_EQ(c.turbulence_intensity->quantiles, alone.turbulence_intensity->quantiles);
    ASSERT_FALSE(c.notes.empty());
    EXPECT_NE(c.notes.front().find("not known for this row: corrected by the reduced forest"), std::string::npos)
        << c.notes.front();
  }
  const auto bytes = m.serialise();
  const auto back = CorrectionModel::parse(bytes, "x.qrf");
  ASSERT_TRUE(back.reduced);
  EXPECT_EQ(back.serialise(), bytes);
  Features peer = full;
  peer.fs = 0;
  EXPECT_EQ(back.correct(peer).velocity->quantiles, m.correct(peer).velocity->quantiles);
  // A reduced model of the extended features is not a reduced model.
  auto wrong = m;
  auto inner = m;
  inner.reduced = nullptr;
  wrong.reduced = std::make_shared<const CorrectionModel>(inner);
  try {
    (void)CorrectionModel::parse(wrong.serialise(), "w.qrf");
    ADD_FAILURE() << "a reduced model of the extended features was read";
  } catch (const awcc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reduced model is not one of the measured features alone"), std::string::npos)
        << e.what();
  }
}

TEST(Correction, ARowWithoutTheTimeScaleGoesToTheReducedModelNamingIt) {
  // A "+scale" model (issue 33) corrects a row that states fs, duration and
  // windows but not T_u / T_W (a file of an earlier pdp, or another tool's)
  // with its reduced model, exactly as that model alone, and the note names
  // the time scale as the one feature missing; the same row with the ratio is
  // the full forest's, whose target here depends on the ratio alone.
  auto m = model_of(
      "extended-yield+lag+scale", 21,
      [](Features& f, std::mt19937_64& g) {
        f.velocity = 1 + 49 * uniform(g);
        f.fs = 1e4 + 1e6 * uniform(g);
        f.duration = 20 + 280 * uniform(g);
        f.windows_total = 1000;
        f.windows_accepted = 10 + static_cast<std::int64_t>(900 * uniform(g));
        f.time_scale_ratio = 0.5 + 19.5 * uniform(g);
      },
      [](const Features& f) { return 1.0 + 0.01 * f.time_scale_ratio; });
  const auto reduced = std::make_shared<const CorrectionModel>(reduced_model());
  m.reduced = reduced;
  Features full = inside();
  full.fs = 5e5;
  full.duration = 100;
  full.windows_total = 1000;
  full.time_scale_ratio = 10.0;
  const auto with = m.correct(full);
  ASSERT_TRUE(with.corrected()) << with.message;
  EXPECT_EQ(with.forest, "awcc");
  Features without = full;
  without.time_scale_ratio = 0.0;
  ASSERT_FALSE(without.value("time_scale_ratio"));
  const auto c = m.correct(without);
  ASSERT_TRUE(c.corrected()) << c.message;
  EXPECT_EQ(c.forest, "awcc-reduced");
  const auto alone = reduced->correct(without);
  ASSERT_TRUE(alone.corrected());
  EXPECT_EQ(c.velocity->quantiles, alone.velocity->quantiles);
  ASSERT_FALSE(c.notes.empty());
  EXPECT_EQ(c.notes.front().rfind("time_scale_ratio not known for this row: corrected by the reduced forest", 0), 0u)
      << c.notes.front();
  EXPECT_NE(c.notes.front().find("process the recording again for the full forest"), std::string::npos);
  // A row missing fs as well is a peer's: no advice to process it again.
  Features peer = without;
  peer.fs = 0;
  const auto p = m.correct(peer);
  ASSERT_TRUE(p.corrected());
  EXPECT_EQ(p.notes.front().find("process the recording again"), std::string::npos) << p.notes.front();
  // Without a reduced model the row is refused, naming the feature.
  m.reduced = nullptr;
  const auto refused = m.correct(without);
  EXPECT_EQ(refused.status, correction::CorrectionStatus::missing_feature);
  EXPECT_NE(refused.message.find("time_scale_ratio"), std::string::npos) << refused.message;
}

TEST(Correction, FsccFeatureSetTwoTakesTheChordTimeAndTheLag) {
  // Set 2 replaces the Sauter diameter from FSCC's velocity by c / F and
  // adds FSCC's lag dx / u_FSCC: both from the measurement, exactly.
  correction::Measurement m;
  m.void_fraction = 0.02;
  m.bubble_count_rate = 16.0;
  m.dx = 7.15e-3;
  m.fscc_velocity = 2.8;
  m.r12_max = 0.04;
  m.fs = 20e3;
  m.duration = 45.0;
  const auto f = correction::make_features(m).features;
  EXPECT_DOUBLE_EQ(*f.value("chord_time"), 0.02 / 16.0);
  EXPECT_DOUBLE_EQ(*f.value("fscc_lag"), 7.15e-3 / 2.8);
  EXPECT_DOUBLE_EQ(*f.value("fscc_d32"), 1.5 * 2.8 * 0.02 / 16.0);
  const auto names = correction::feature_set_names("fscc-2");
  ASSERT_EQ(names.size(), 9u);
  for (const auto& n : names) EXPECT_TRUE(f.value(n)) << n;
  EXPECT_EQ(std::find(names.begin(), names.end(), "fscc_d32"), names.end());
  // Without bubbles or an FSCC velocity, neither is known.
  EXPECT_FALSE(Features{}.value("chord_time"));
  EXPECT_FALSE(Features{}.value("fscc_lag"));
  EXPECT_EQ(correction::feature_value_text("fscc_lag", 2.5e-3), "fscc_lag = 2.5 ms");
}

TEST(Correction, TheWeightingAsAFeatureCorrectsEitherAndMixesAnUnknownOne) {
  // A model whose velocity target is 1 for duration-weighted rows and 0.95
  // for unweighted ones (unweighted moments high by about Tu^2): each
  // weighting is corrected as its own, a row of unknown weighting by the
  // mixture of both (its quantiles spanning both answers, with a note), and
  // the processing check does not refuse the other weighting.
  auto m = model_of("measured+weighting", 12, [](Features& f, std::mt19937_64& g) {
    f.velocity = 1 + 49 * uniform(g);
    f.awcc_unweighted = uniform(g) < 0.5 ? 1 : 0;
  }, [](const Features& f) { return f.awcc_unweighted == 1 ? 0.95 : 1.0; });
  ASSERT_TRUE(m.takes_weighting());
  EXPECT_EQ(m.weighting_feature(), 7u);
  Features f = inside();
  f.awcc_unweighted = 0;
  const auto weighted = m.correct(f);
  f.awcc_unweighted = 1;
  const auto unweighted = m.correct(f);
  f.awcc_unweighted = -1;
  const auto unknown = m.correct(f);
  ASSERT_TRUE(weighted.corrected() && unweighted.corrected()) << weighted.message << unweighted.message;
  EXPECT_DOUBLE_EQ(weighted.velocity->median(), 10.0);
  EXPECT_DOUBLE_EQ(unweighted.velocity->median(), 9.5);
  ASSERT_TRUE(unknown.velocity);
  EXPECT_DOUBLE_EQ(unknown.velocity->quantiles.front(), 9.5);
  EXPECT_DOUBLE_EQ(unknown.velocity->quantiles.back(), 10.0);
  ASSERT_FALSE(unknown.notes.empty());
  EXPECT_NE(unknown.notes.back().find("the setting weighting"), std::string::npos) << unknown.notes.back();
  correction::Processing none;
  none.weighting = awcc::Weighting::none;
  EXPECT_EQ(m.mismatch(none), "");
  none.filter_a = 0.3;
  EXPECT_NE(m.mismatch(none).find("filter A"), std::string::npos);
  EXPECT_EQ(correction::feature_set_of(correction::feature_set_names("extended-yield+weighting")),
            "extended-yield+weighting");
  // A measurement says its weighting through the feature.
  correction::Measurement meas;
  meas.velocity = 3.0;
  meas.turbulence_intensity = 0.2;
  meas.void_fraction = 0.1;
  meas.bubble_count_rate = 50.0;
  EXPECT_FALSE(correction::make_features(meas).features.value("awcc_unweighted"));
  meas.weighting = awcc::Weighting::none;
  EXPECT_EQ(*correction::make_features(meas).features.value("awcc_unweighted"), 1.0);
}

// The first row of a corrected CSV, cell by column name.
std::map<std::string, std::string> first_row_by_name(const std::string& text) {
  const auto first = text.find('\n');
  const auto names = awcc::split_cells(text.substr(0, first));
  const auto cells = awcc::split_cells(text.substr(first + 1, text.find('\n', first + 1) - first - 1));
  std::map<std::string, std::string> by_name;
  for (std::size_t i = 0; i < names.size() && i < cells.size(); ++i) by_name[names[i]] = cells[i];
  return by_name;
}

TEST(Correction, AnotherToolsCsvGivesTheRecordsFeaturesByColumnOrOption) {
  // An extended-yield model (data yield = accepted / formed windows) and the
  // CSV other AWCC tools write: with the columns fs, duration,
  // awcc_windows_accepted and awcc_windows_total a row is corrected; without
  // the formed windows it says the data yield is missing and how to give it;
  // fs and duration may come from pdp correct's options instead.
  const auto m = model_of("extended-yield", 3, [](Features& f, std::mt19937_64& g) {
    f.velocity = 1 + 9 * uniform(g);
    f.turbulence_intensity = 0.05 + 0.3 * uniform(g);
    f.void_fraction = 0.01 + 0.3 * uniform(g);
    f.d32 = 1e-3 + 5e-3 * uniform(g);
    f.fs = 1e4 + 1e5 * uniform(g);
    f.duration = 20 + 100 * uniform(g);
    f.windows_accepted = 10 + static_cast<std::int64_t>(100 * uniform(g));
    f.windows_total = f.windows_accepted + static_cast<std::int64_t>(100 * uniform(g));
  }, [](const Features&) { return 1.0; });
  correction::RowDefaults d;
  d.dx = 5e-3, d.dy = 1e-3, d.np = 10;
  const std::string head = "u [m/s],u_rms [m/s],c [-],d_32a [m]";
  const std::string row = "5,1,0.1,0.003";
  auto corrected = [&](const std::string& extra_head, const std::string& extra_row, const correction::RowDefaults& defaults) {
    return first_row_by_name(
        correction::correct_profile_csv(m, head + extra_head + "\n" + row + extra_row + "\n", defaults, "tool.csv").text);
  };
  auto all = corrected(",fs,duration,awcc_windows_accepted,awcc_windows_total", ",50000,60,40,80", d);
  EXPECT_EQ(all["correction_status [-]"], "corrected") << all["correction_reason [-]"];
  auto no_total = corrected(",fs,duration,awcc_windows_accepted", ",50000,60,40", d);
  EXPECT_EQ(no_total["correction_status [-]"], "missing_feature");
  EXPECT_NE(no_total["correction_reason [-]"].find("awcc_windows_total"), std::string::npos) << no_total["correction_reason [-]"];
  auto given = d;
  given.fs = 50000, given.duration = 60;
  auto by_option = corrected(",awcc_windows_accepted,awcc_windows_total", ",40,80", given);
  EXPECT_EQ(by_option["correction_status [-]"], "corrected") << by_option["correction_reason [-]"];
  EXPECT_EQ(by_option["u_corrected [m/s]"], all["u_corrected [m/s]"]);
  // A count that is not a whole number is refused, naming the row.
  EXPECT_THROW(corrected(",fs,duration,awcc_windows_accepted,awcc_windows_total", ",50000,60,40.5,80", d),
               awcc::InputError);
}

TEST(Correction, AProfileCsvStatesChansonsTuByItsColumn) {
  // A "+chanson" model and pdp's profile CSV: Chanson's Tu is read from its
  // column (an empty cell is FSCC's undefined Tu, which the feature takes as
  // 0); a CSV without the column (an earlier pdp's) does not state it, and
  // its rows go to the reduced forest, or are refused naming the feature
  // without one. The velocity target depends on Chanson's Tu alone, so the
  // row's corrected u says which value the forest saw.
  auto m = model_of(
      "extended+fscc+chanson", 23,
      [](Features& f, std::mt19937_64& g) {
        f.fs = 1e5 + 9e5 * uniform(g);
        f.duration = 20 + 280 * uniform(g);
        f.windows_accepted = 100 + static_cast<std::int64_t>(800 * uniform(g));
        f.fscc_velocity = f.velocity * (0.9 + 0.2 * uniform(g));
        f.r12_max = 0.2 + 0.6 * uniform(g);
        const double draw = uniform(g);
        f.tu_chanson = draw < 0.3 ? 0.0 : 0.5 * draw;
      },
      [](const Features& f) { return 1.0 + 0.2 * f.tu_chanson.value_or(-1.0); });
  m.reduced = std::make_shared<const CorrectionModel>(reduced_model());
  // inside()'s row: u 10 m/s, Tu 0.2, c 0.2, d32 = 1.5 u c / F = 5 mm at F = 600 Hz.
  const std::string head =
      "void_fraction,bubble_count_rate,awcc_velocity,awcc_turbulence_intensity,awcc_windows_accepted,awcc_status,"
      "fs,duration,dx,dy,np,fscc_status,fscc_velocity,fscc_r12_max";
  const std::string row = "0.2,600,10,0.2,500,ok,500000,100,0.005,0.001,10,ok,10,0.5";
  auto corrected = [&](const std::string& extra_head, const std::string& extra_row) {
    return first_row_by_name(
        correction::correct_profile_csv(m, head + extra_head + "\n" + row + extra_row + "\n", {}, "p.csv").text);
  };
  auto u_of = [](std::map<std::string, std::string>& r) { return awcc::cell_number(r["corrected_velocity"]).value_or(-1); };
  auto stated = corrected(",fscc_turbulence_intensity_chanson", ",0.4");
  ASSERT_EQ(stated["correction_status"], "corrected") << stated["correction_reason"];
  EXPECT_EQ(stated["correction_forest"], "awcc");
  // The forest's leaves near Chanson's Tu 0.4 hold targets 1.07-1.10: u 10.7-11.0.
  EXPECT_NEAR(u_of(stated), 10.0 * (1 + 0.2 * 0.4), 0.15);
  auto undefined = corrected(",fscc_turbulence_intensity_chanson", ",");
  ASSERT_EQ(undefined["correction_status"], "corrected") << undefined["correction_reason"];
  EXPECT_EQ(undefined["correction_forest"], "awcc");
  EXPECT_NEAR(u_of(undefined), 10.0, 0.05);  // the draws at 0 learnt the target 1 exactly
  auto absent = corrected("", "");
  ASSERT_EQ(absent["correction_status"], "corrected") << absent["correction_reason"];
  EXPECT_EQ(absent["correction_forest"], "awcc-reduced");
  EXPECT_NE(absent["correction_notes"].find("fscc_tu_chanson"), std::string::npos) << absent["correction_notes"];
  m.reduced = nullptr;
  auto refused = corrected("", "");
  EXPECT_EQ(refused["correction_status"], "missing_feature");
  EXPECT_NE(refused["correction_reason"].find("fscc_tu_chanson"), std::string::npos) << refused["correction_reason"];
}

TEST(Correction, DropletFlowIsNamedAsOutsideWhatTheModelLearnt) {
  const auto m = small_model();
  auto f = inside();
  f.void_fraction = 0.75;
  const auto c = m.correct(f);
  EXPECT_EQ(c.status, correction::CorrectionStatus::outside_training_range);
  EXPECT_NE(c.message.find("droplets in air"), std::string::npos) << c.message;
  f.void_fraction = 0.5;  // outside this small model's range too, but not droplet flow
  EXPECT_EQ(m.correct(f).message.find("droplets"), std::string::npos);
}

// Format 2 as model.hpp documents it, written here independently of the
// library's writer (which writes format 3 only).
std::vector<std::uint8_t> format2_bytes(const CorrectionModel& m) {
  std::vector<std::uint8_t> p;
  auto u8 = [&](std::uint8_t v) { p.push_back(v); };
  auto u32 = [&](std::uint32_t v) { for (int k = 0; k < 4; ++k) p.push_back(static_cast<std::uint8_t>(v >> (8 * k))); };
  auto u64 = [&](std::uint64_t v) { u32(static_cast<std::uint32_t>(v)), u32(static_cast<std::uint32_t>(v >> 32)); };
  auto f64 = [&](double v) { std::uint64_t b; std::memcpy(&b, &v, 8); u64(b); };
  auto text = [&](const std::string& t) { u32(static_cast<std::uint32_t>(t.size())); p.insert(p.end(), t.begin(), t.end()); };
  text(m.provenance);
  u32(static_cast<std::uint32_t>(m.ranges.size()));
  for (const auto& r : m.ranges) text(r.name), f64(r.min), f64(r.max);
  f64(m.range_margin);
  u64(static_cast<std::uint64_t>(m.min_windows));
  f64(m.processing.filter_a);
  u8(m.processing.roc ? 1 : 0), u8(0), u8(0), u8(0);
  u32(2);
  for (const auto& [name, form, forest] : {std::tuple{"velocity", m.velocity_form, &m.velocity},
                                           std::tuple{"turbulence_intensity", m.turbulence_form, &m.turbulence_intensity}}) {
    text(name);
    u8(static_cast<std::uint8_t>(form));
    u32(static_cast<std::uint32_t>(forest->features()));
    const auto targets = forest->targets();
    u64(targets.size());
    for (double y : targets) f64(y);
    const auto trees = forest->trees();
    u32(static_cast<std::uint32_t>(trees.size()));
    u8(2);
    for (const auto& t : trees) {
      u32(static_cast<std::uint32_t>(t.nodes.size()));
      for (const auto& n : t.nodes) {
        if (n.feature < 0) {
          u8(0xff), u32(n.left), u32(n.right);
        } else {
          u8(static_cast<std::uint8_t>(n.feature)), f64(n.threshold), u32(n.left);
        }
      }
      u64(t.leaf_rows.size());
      for (auto r : t.leaf_rows) u8(static_cast<std::uint8_t>(r)), u8(static_cast<std::uint8_t>(r >> 8));
    }
  }
  std::vector<std::uint8_t> file{'p', 'd', 'p', '-', 'q', 'r', 'f', '\n'};
  for (int k = 0; k < 4; ++k) file.push_back(static_cast<std::uint8_t>(2u >> (8 * k)));
  for (int k = 0; k < 8; ++k) file.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(p.size()) >> (8 * k)));
  file.insert(file.end(), p.begin(), p.end());
  const auto crc = correction::crc32(file.data(), file.size());
  for (int k = 0; k < 4; ++k) file.push_back(static_cast<std::uint8_t>(crc >> (8 * k)));
  return file;
}

TEST(Correction, Format2FilesStillCorrectAsTheyDid) {
  const auto m = small_model();
  const auto old = CorrectionModel::parse(format2_bytes(m), "old.qrf");
  EXPECT_EQ(old.ranges.size(), 7u);
  EXPECT_TRUE(old.calibration.empty());
  EXPECT_FALSE(old.fscc);
  auto f = inside();  // no fs or duration: the seven features suffice
  for (double u : {5.0, 10.0, 30.0}) {
    f.velocity = u;
    const auto a = m.correct(f), b = old.correct(f);
    ASSERT_TRUE(b.corrected()) << b.message;
    EXPECT_EQ(a.velocity->quantiles, b.velocity->quantiles);
    EXPECT_EQ(a.turbulence_intensity->quantiles, b.turbulence_intensity->quantiles);
  }
  // Saved again, it is format 5 with the same forests.
  EXPECT_EQ(old.serialise(), m.serialise());
}

TEST(Correction, TheShippedModelCorrectsTheRecordsLabsMake) {
  // Issue 18: the data yield as the record feature (chosen by
  // cross-validation, docs/validation.md), rows from 10 accepted windows, an
  // FSCC forest, calibrated intervals; issue 33: the lag in samples and the
  // weighting, and a reduced model for peers' rows; the time-scale ratio
  // (the campaign's complete candidate). A 45 s, 20 kHz row with 30 of 300
  // windows is corrected by the AWCC forest, with quantiles in order.
  const auto m = CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  EXPECT_EQ(correction::feature_set_of([&] {
              std::vector<std::string> n;
              for (const auto& r : m.ranges) n.push_back(r.name);
              return n;
            }()),
            "extended-yield+lag+scale+weighting");
  EXPECT_EQ(m.min_windows, 10);
  ASSERT_TRUE(m.fscc.has_value());
  ASSERT_TRUE(m.reduced);
  EXPECT_FALSE(m.calibration.empty());
  Features f = lab_row();
  const auto c = m.correct(f);
  ASSERT_TRUE(c.corrected()) << c.message;
  EXPECT_EQ(c.forest, "awcc");
  for (const auto* q : {&*c.velocity, &*c.turbulence_intensity})
    EXPECT_TRUE(std::is_sorted(q->quantiles.begin(), q->quantiles.end()));
  // Droplet flow (c above the campaign's 0.6) stays flagged.
  f.void_fraction = 0.7;
  EXPECT_EQ(m.correct(f).status, correction::CorrectionStatus::outside_training_range);
}

TEST(Correction, TheModelForSixtySecondRecordsAt500kHzStillCorrects) {
  // The model shipped before issue 18 (seven measured features, at least 100
  // windows, no FSCC forest): old files keep working.
  const auto m = CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc-60s-500kHz.qrf");
  EXPECT_EQ(m.ranges.size(), 7u);
  EXPECT_EQ(m.min_windows, 100);
  EXPECT_FALSE(m.fscc.has_value());
  const auto c = m.correct(inside());
  EXPECT_TRUE(c.corrected()) << c.message;
}

}  // namespace

TEST(Correction, OlderFilesTakeTheirNinetyPercentOffsetBetweenTheirEightyAndNinetyFive) {
  // Files before format 7 hold the 50, 80 and 95 % offsets only; the 90 %
  // one is read as their interpolation in the normal score, where z(0.90) =
  // 1.6449 lies 0.5355 of the way from z(0.80) = 1.2816 to z(0.95) = 1.9600.
  // The model shipped before the time-prior retrain is of format 6.
  const auto path = pdp_test::source_dir() / "samples" / "model" / "awcc.qrf";
  std::ifstream in(path, std::ios::binary);
  char head[12] = {};
  in.read(head, 12);
  ASSERT_EQ(head[8], 6) << path << " is no longer of format 6: point this test at the file kept from before";
  const auto m = CorrectionModel::load(path);
  ASSERT_FALSE(m.calibration.empty());
  for (const auto* groups : {&m.calibration.velocity, &m.calibration.turbulence_intensity}) {
    for (const auto& o : *groups) {
      const double w = (1.6448536269514722 - 1.2815515655446004) / (1.959963984540054 - 1.2815515655446004);
      EXPECT_NEAR(w, 0.5355, 1e-4);
      EXPECT_NEAR(o[correction::interval90], (1 - w) * o[correction::interval80] + w * o[correction::interval95], 1e-15);
    }
  }
  // A corrected row's nine quantiles are in order, the 90 % interval inside the 95 % and around the 80 %.
  const auto c = m.correct(lab_row());
  ASSERT_TRUE(c.corrected()) << c.message;
  const auto& q = c.velocity->quantiles;
  EXPECT_TRUE(std::is_sorted(q.begin(), q.end()));
  EXPECT_LE(c.velocity->lower(correction::interval95), c.velocity->lower(correction::interval90));
  EXPECT_LE(c.velocity->lower(correction::interval90), c.velocity->lower(correction::interval80));
  // Written again, it is format 7 with the same numbers.
  const auto back = CorrectionModel::parse(m.serialise(), "again.qrf");
  EXPECT_EQ(back.calibration.velocity, m.calibration.velocity);
}
