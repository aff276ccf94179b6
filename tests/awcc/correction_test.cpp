#include "awcc/correction.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <random>

#include "test_paths.hpp"

namespace {

using awcc::CorrectionFeatures;
using awcc::CorrectionModel;

// A small model: truth = measured * (1 + 0.1 * dy/2mm) + noise, Tu truth =
// measured Tu + 0.02.
CorrectionModel small_model(std::uint64_t seed = 3) {
  std::mt19937_64 g(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  awcc::TrainingData v, t;
  v.features = t.features = CorrectionFeatures::count;
  CorrectionModel m;
  std::array<double, 7> lo, hi;
  lo.fill(1e300);
  hi.fill(-1e300);
  for (int i = 0; i < 400; ++i) {
    CorrectionFeatures f;
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
    v.y.push_back(awcc::to_target(m.velocity_form, true_u, f.velocity));
    t.y.push_back(awcc::to_target(m.turbulence_form, f.turbulence_intensity + 0.02, f.turbulence_intensity));
  }
  for (std::size_t j = 0; j < 7; ++j) m.ranges.push_back({CorrectionFeatures::names[j], lo[j], hi[j]});
  awcc::ForestOptions o;
  o.trees = 10;
  o.seed = seed;
  m.velocity = awcc::QuantileForest::train(v, o);
  m.turbulence_intensity = awcc::QuantileForest::train(t, o);
  m.provenance = "test model";
  return m;
}

CorrectionFeatures inside() {
  CorrectionFeatures f;
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

TEST(Correction, Crc32MatchesTheStandardCheckValue) {
  const char* text = "123456789";
  EXPECT_EQ(awcc::crc32(reinterpret_cast<const std::uint8_t*>(text), 9), 0xCBF43926u);
}

TEST(Correction, RoundTripGivesTheSameBytesAndPredictions) {
  const auto m = small_model();
  const auto bytes = m.serialise();
  const auto back = CorrectionModel::parse(bytes, "mem");
  EXPECT_EQ(back.serialise(), bytes);
  EXPECT_EQ(back.provenance, "test model");
  const auto a = m.correct(inside()), b = back.correct(inside());
  ASSERT_TRUE(a.in_range);
  ASSERT_TRUE(b.in_range);
  EXPECT_EQ(a.velocity->quantiles, b.velocity->quantiles);
  EXPECT_EQ(a.turbulence_intensity->quantiles, b.turbulence_intensity->quantiles);
  // The learnt factor: truth ~ measured * 1.05 at dy = 1 mm (within the leaf's spread).
  EXPECT_NEAR(a.velocity->median() / 10.0, 1.05, 0.03);
  EXPECT_NEAR(a.turbulence_intensity->median(), 0.22, 1e-12);
}

// More than 65,536 training rows: held rows take 4 bytes on file.
TEST(Correction, LargeTrainingSetsRoundTrip) {
  auto m = small_model();
  awcc::TrainingData big;
  big.features = CorrectionFeatures::count;
  std::mt19937_64 g(2);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 70000; ++i) {
    for (int j = 0; j < big.features; ++j) big.x.push_back(u(g));
    big.y.push_back(u(g));
  }
  awcc::ForestOptions o;
  o.trees = 2;
  o.min_leaf = 50;
  m.velocity = awcc::QuantileForest::train(big, o);
  const auto bytes = m.serialise();
  const auto back = CorrectionModel::parse(bytes, "big");
  EXPECT_EQ(back.velocity.trees()[1].leaf_rows, m.velocity.trees()[1].leaf_rows);
  EXPECT_EQ(back.serialise(), bytes);
  std::uint32_t largest = 0;
  for (auto r : back.velocity.trees()[0].leaf_rows) largest = std::max(largest, r);
  EXPECT_GT(largest, 65535u);
}

TEST(Correction, FileIsLittleEndianWhateverTheMachine) {
  const auto bytes = small_model().serialise();
  ASSERT_GT(bytes.size(), 24u);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 8), "pdp-qrf\n");
  // Format version 1 as u32 little-endian.
  EXPECT_EQ(bytes[8], 1);
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
  newer[8] = 2;
  EXPECT_NE(message(newer).find("version 2"), std::string::npos) << message(newer);
  // A structural fault with a valid checksum: the reader checks the trees too.
  auto forged = bytes;
  // The first tree's root node follows the velocity targets; find it by
  // serialising with a recognisable threshold instead of guessing offsets:
  // rewrite the first node's left child to 0 (a cycle) and fix the CRC.
  auto m = small_model();
  auto trees = m.velocity.trees();
  trees[0].nodes[0].left = 0;
  // assemble refuses it directly...
  EXPECT_THROW((void)awcc::QuantileForest::assemble(7, m.velocity.targets(), trees), std::invalid_argument);
  // ...and a file carrying it is refused as damaged. Build the file bytes by
  // patching the serialised root (same size) and recomputing the checksum.
  const auto good = m.serialise();
  // A split node on file: u8 feature, f64 threshold, u32 left child.
  std::vector<std::uint8_t> node(13);
  const auto& root = m.velocity.trees()[0].nodes[0];
  node[0] = static_cast<std::uint8_t>(root.feature);
  std::uint64_t bits;
  std::memcpy(&bits, &root.threshold, 8);
  for (int i = 0; i < 8; ++i) node[1 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(bits >> (8 * i));
  for (int i = 0; i < 4; ++i) node[9 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(root.left >> (8 * i));
  const auto at = std::search(good.begin(), good.end(), node.begin(), node.end());
  ASSERT_NE(at, good.end());
  forged = good;
  const auto offset = static_cast<std::size_t>(at - good.begin());
  for (int i = 0; i < 4; ++i) forged[offset + 9 + static_cast<std::size_t>(i)] = 0;
  const auto crc = awcc::crc32(forged.data(), forged.size() - 4);
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
  EXPECT_FALSE(c.in_range);
  EXPECT_NE(c.reason.find("void_fraction = 0.9"), std::string::npos) << c.reason;
  EXPECT_FALSE(c.velocity.has_value());
  f = inside();
  f.windows_accepted = 99;
  c = m.correct(f);
  EXPECT_FALSE(c.in_range);
  EXPECT_NE(c.reason.find("99 accepted windows"), std::string::npos) << c.reason;
  // Within the margin of 1 % of the span below the smallest dy: in range;
  // beyond it: out.
  f = inside();
  const auto& dy = m.ranges[5];
  f.dy = dy.min - 0.5 * m.range_margin * (dy.max - dy.min);
  EXPECT_TRUE(m.correct(f).in_range);
  f.dy = dy.min - 1.5 * m.range_margin * (dy.max - dy.min);
  EXPECT_FALSE(m.correct(f).in_range);
  f = inside();
  f.velocity = std::nan("");
  EXPECT_FALSE(m.correct(f).in_range);
}

TEST(Correction, TargetFormsInvert) {
  for (auto form : {awcc::TargetForm::value, awcc::TargetForm::ratio, awcc::TargetForm::difference}) {
    const double t = awcc::to_target(form, 7.5, 6.0);
    EXPECT_DOUBLE_EQ(awcc::from_target(form, t, 6.0), 7.5) << awcc::to_string(form);
  }
}

TEST(Correction, JsonHasTheDocumentedKeys) {
  const auto c = small_model().correct(inside());
  const auto j = awcc::to_json(c);
  EXPECT_TRUE(j["in_range"].get<bool>());
  EXPECT_TRUE(j["reason"].is_null());
  for (const char* q : {"velocity", "turbulence_intensity"}) {
    const auto& quantiles = j[q]["quantiles"];
    ASSERT_EQ(quantiles.size(), 7u);
    for (const char* key : {"0.025", "0.1", "0.25", "0.5", "0.75", "0.9", "0.975"}) ASSERT_TRUE(quantiles.contains(key)) << key;
    EXPECT_EQ(j[q]["median"], quantiles["0.5"]);
  }
}

TEST(Correction, FeaturesOfAProcessedRecording) {
  awcc::ProcessResult r;
  std::string why;
  EXPECT_FALSE(awcc::correction_features(r, &why));
  EXPECT_NE(why.find("AWCC was not run"), std::string::npos);
  r.dx = 5e-3;
  r.dy = 1e-3;
  r.tips.resize(2);
  r.tips[0].phase.void_fraction = 0.2;
  r.tips[0].phase.bubble_count_rate = 600.0;
  r.awcc = awcc::AwccResult{};
  r.awcc->defined = true;
  r.awcc->velocity = 10.0;
  r.awcc->turbulence_intensity = 0.25;
  r.awcc->np = 12;
  r.awcc->windows_accepted = 321;
  const auto f = awcc::correction_features(r, &why);
  ASSERT_TRUE(f);
  EXPECT_DOUBLE_EQ(f->d32, 1.5 * 10.0 * 0.2 / 600.0);
  EXPECT_EQ(f->np, 12.0);
  EXPECT_EQ(f->windows_accepted, 321);
  EXPECT_EQ(f->dy, 1e-3);
}

}  // namespace
