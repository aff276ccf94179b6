// The trust rules of the correction (correction/model.hpp: the envelope and
// one mode), the multimodality test (correction/modality.hpp), records
// longer than the training records, and the messages (issue 29, cases 1 and 6).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <map>
#include <random>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "correction/modality.hpp"
#include "correction/model.hpp"
#include "correction/training.hpp"
#include "test_paths.hpp"

namespace {

using correction::CorrectionModel;
using correction::CorrectionStatus;
using correction::Features;
using correction::WeightedDistribution;

// n equal weights at the quantiles (i + 0.5) / n of a distribution: a sample
// with no sampling noise, so that its smoothed interval densities are those
// of the density itself.
WeightedDistribution grid_sample(int n, const std::function<double(double)>& inverse_cdf) {
  WeightedDistribution d;
  for (int i = 0; i < n; ++i) {
    d.values.push_back(inverse_cdf((i + 0.5) / n));
    d.weights.push_back(1.0 / n);
  }
  return d;
}

double normal_quantile(double p) {
  // Bisection on erfc: slow and exact enough for a test.
  double lo = -10.0, hi = 10.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TEST(Modality, UnimodalDensitiesNeverDip) {
  // modality.hpp proves d_k >= min(max left, max right) for a unimodal
  // density; a noiseless sample of one keeps the ratio at 1 to within the
  // smoothing of its atoms.
  const std::vector<std::pair<const char*, std::function<double(double)>>> shapes{
      {"normal", normal_quantile},
      {"uniform", [](double p) { return p; }},
      {"exponential", [](double p) { return -std::log(1.0 - p); }},
      {"skewed triangle", [](double p) { return std::sqrt(p); }},
      {"lognormal", [](double p) { return std::exp(0.8 * normal_quantile(p)); }}};
  for (const auto& [name, q] : shapes) {
    for (bool log_scale : {false, true}) {
      if (log_scale && std::string(name) != "lognormal") continue;
      const auto d = correction::dip(grid_sample(4000, q), log_scale);
      EXPECT_GE(d.ratio, 0.98) << name << (log_scale ? " (log scale)" : "");
    }
  }
}

TEST(Modality, TwoSeparatedModesDipBelowTheLimit) {
  // Half the weight near 1, half near 3 (sd 0.1 each). The 0.5 quantile
  // lies where the last value of the first mode, spread to the midpoint of
  // the gap, ends: the interval 0.25-0.5 spans half the gap (about 1) with a
  // quarter of the weight, against 0.15 over 0.06 below it.
  const auto d = correction::dip(grid_sample(2000,
                                             [](double p) {
                                               return p < 0.5 ? 1.0 + 0.1 * normal_quantile(2 * p)
                                                              : 3.0 + 0.1 * normal_quantile(2 * p - 1);
                                             }),
                                 false);
  EXPECT_LT(d.ratio, 0.2);
  // The sparse interval lies between the modes: 0.25-0.5 or 0.5-0.75.
  EXPECT_TRUE(d.interval == 2 || d.interval == 3) << d.interval;
  EXPECT_LT(d.ratio, correction::multimodal_dip_limit);
}

TEST(Modality, RatioOfAConstructedSampleByHand) {
  // Atoms at 0..9: 0.3 at 0 and at 9, 0.05 at each of 1..8. Smoothed, the
  // density is 0.3 per unit on [-0.5, 0.5] and [8.5, 9.5], 0.05 between.
  // Quantiles: 0.025 -> -0.5 + 0.025/0.3, 0.1 -> -0.5 + 0.1/0.3, 0.25 ->
  // -0.5 + 0.25/0.3, 0.5 -> 0.5 + 0.2/0.05 = 4.5, 0.75 -> 8.5 + 0.05/0.3,
  // 0.9 -> 8.5 + 0.2/0.3, 0.975 -> 8.5 + 0.275/0.3. Interval densities 0.3,
  // 0.3, 0.25/4.1667 = 0.06, 0.06, 0.3, 0.3: ratio 0.06 / 0.3 = 0.2, first at
  // interval 2.
  WeightedDistribution d;
  for (int v = 0; v <= 9; ++v) {
    d.values.push_back(v);
    d.weights.push_back(v == 0 || v == 9 ? 0.3 : 0.05);
  }
  const auto m = correction::dip(d, false);
  EXPECT_NEAR(m.ratio, 0.2, 1e-12);
  EXPECT_EQ(m.interval, 2u);
  const std::array<double, 7> q{-0.5 + 0.025 / 0.3, -0.5 + 0.1 / 0.3, -0.5 + 0.25 / 0.3, 4.5,
                                8.5 + 0.05 / 0.3,   8.5 + 0.2 / 0.3,  8.5 + 0.275 / 0.3};
  for (std::size_t k = 0; k < q.size(); ++k) EXPECT_NEAR(m.quantiles[k], q[k], 1e-12) << k;
  // On the log scale the same sample, shifted to be positive, gives the
  // ratio of the logarithms' spacings: not the same number.
  for (double& v : d.values) v += 1.0;
  EXPECT_NE(correction::dip(d, true).ratio, correction::dip(d, false).ratio);
  EXPECT_NEAR(correction::dip(d, false).ratio, 0.2, 1e-12);  // a shift changes nothing
}

TEST(Modality, ValuesApartByRoundingAreOneAndOneValueDoesNotDip) {
  // Tu targets of one truth: t = (0.2 + 0.02) - 0.2 and the like differ in
  // their last bits; spread between them they would be a density without bound.
  WeightedDistribution d;
  for (double tu : {0.1, 0.2, 0.3, 0.25, 0.15}) d.values.push_back((tu + 0.02) - tu);
  std::sort(d.values.begin(), d.values.end());
  d.weights.assign(d.values.size(), 1.0 / static_cast<double>(d.values.size()));
  EXPECT_EQ(correction::dip(d, false).ratio, 1.0);
  WeightedDistribution one{{1.5}, {1.0}};
  EXPECT_EQ(correction::dip(one, true).ratio, 1.0);
}

// A model of the seven measured features over `rows` random rows whose
// velocity target (ratio) is `velocity_target(i)` and whose Tu target
// (difference) is `tu_target(i)`; the features carry no information, so the
// forest's distribution at any row is the targets' own.
CorrectionModel model_of(const std::function<double(int)>& velocity_target,
                         const std::function<double(int)>& tu_target, int rows = 300) {
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  correction::TrainingData v, t;
  v.features = t.features = Features::count;
  CorrectionModel m;
  for (int j = 0; j < Features::count; ++j) m.ranges.push_back({Features::names[static_cast<std::size_t>(j)], 0.0, 10.0});
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < Features::count; ++j) {
      const double x = u(g);
      v.x.push_back(x);
      t.x.push_back(x);
    }
    v.y.push_back(velocity_target(i));
    t.y.push_back(tu_target(i));
  }
  correction::ForestOptions o;
  o.trees = 20;
  o.min_leaf = rows + 1;  // one leaf: the root holds every row
  m.velocity = correction::QuantileForest::train(v, o);
  m.turbulence_intensity = correction::QuantileForest::train(t, o);
  m.min_windows = 10;
  m.use_training_envelopes();
  return m;
}

// A correction's profile CSV cells by column name (empty when the cells
// and the declared columns differ in number: the caller checks the size).
std::map<std::string, std::string, std::less<>> csv_cells_by_column(const correction::Correction& c) {
  const auto cells = awcc::split_cells(correction::correction_csv_cells(c));
  const auto columns = correction::correction_csv_columns();
  std::map<std::string, std::string, std::less<>> out;
  if (cells.size() != columns.size()) return out;
  for (std::size_t k = 0; k < columns.size(); ++k) out[std::string(columns[k].name)] = cells[k];
  return out;
}

Features middle() {
  Features f;
  f.velocity = 2.0;
  f.turbulence_intensity = 0.2;
  f.void_fraction = f.d32 = f.dx = f.dy = f.np = 0.5;
  f.windows_accepted = 100;
  return f;
}

TEST(TrustRules, EnvelopeHoldsAtItsLimitAndBreaksJustBeyond) {
  // Every velocity target 1.2 (truth = 1.2 x AWCC), Tu +0.05: the median
  // moves the velocity by +20 % and Tu by +0.05, whatever the row.
  auto m = model_of([](int) { return 1.2; }, [](int) { return 0.05; });
  const double shift = 1.2 - 1.0, tu_shift = 0.05;
  auto& cal = m.calibration;
  cal.envelope_from_training = false;
  cal.turbulence_envelope = {{0.0, tu_shift}};
  for (double above : {shift, std::nextafter(shift, 1.0), 0.3}) {
    cal.velocity_envelope = {{0.1, above}};
    const auto c = m.correct(middle());
    EXPECT_TRUE(c.corrected()) << above << ": " << c.message;
  }
  cal.velocity_envelope = {{0.1, std::nextafter(shift, 0.0)}};
  auto c = m.correct(middle());
  EXPECT_EQ(c.status, CorrectionStatus::untrusted);
  EXPECT_TRUE(c.outside_envelope);
  EXPECT_FALSE(c.multimodal);
  EXPECT_FALSE(c.corrected());
  EXPECT_NE(c.message.find("outside the envelope: the AWCC forest's velocity median 2.4 m/s is +20 % from AWCC's 2 m/s"),
            std::string::npos)
      << c.message;
  EXPECT_NE(c.message.find("within -10 % to +20 % of the measurement for 99.5 % of them"), std::string::npos) << c.message;
  EXPECT_EQ(c.why_not(), "untrusted: " + c.message);
  // The quantiles stay for the report to draw apart; nothing presents them as corrected.
  ASSERT_TRUE(c.velocity && c.turbulence_intensity);
  EXPECT_DOUBLE_EQ(c.velocity->quantiles[3], 2.4);
  const auto j = correction::to_json(c);
  EXPECT_EQ(j["status"], "untrusted");
  EXPECT_FALSE(j["in_range"].get<bool>());
  EXPECT_TRUE(j["velocity"]["median"].is_null());
  EXPECT_DOUBLE_EQ(j["velocity"]["quantiles"]["0.5"].get<double>(), 2.4);
  auto cell = csv_cells_by_column(c);
  ASSERT_EQ(cell.size(), correction::correction_csv_columns().size());
  EXPECT_EQ(cell["corrected_velocity"], "");
  EXPECT_EQ(cell["corrected_velocity_q0.5"], "2.4");
  EXPECT_EQ(cell["correction_status"], "untrusted");
  EXPECT_EQ(cell["correction_in_range"], "0");
  // Below: targets 0.8 move the velocity by -20 %.
  auto low = model_of([](int) { return 0.8; }, [](int) { return 0.0; });
  low.calibration.envelope_from_training = false;
  low.calibration.turbulence_envelope = {{0.0, 0.0}};
  low.calibration.velocity_envelope = {{1.0 - 0.8, 0.0}};
  EXPECT_TRUE(low.correct(middle()).corrected());
  low.calibration.velocity_envelope = {{std::nextafter(1.0 - 0.8, 0.0), 0.0}};
  EXPECT_EQ(low.correct(middle()).status, CorrectionStatus::untrusted);
  // Tu's envelope alone makes the row untrusted, and says Tu's numbers.
  cal.velocity_envelope = {{0.1, 0.3}};
  cal.turbulence_envelope = {{0.0, 0.04}};
  c = m.correct(middle());
  EXPECT_EQ(c.status, CorrectionStatus::untrusted);
  EXPECT_NE(c.message.find("the AWCC forest's Tu median 0.25 is +0.05 from AWCC's 0.2"), std::string::npos) << c.message;
  // Both broken: the rule named once, a clause for each.
  cal.velocity_envelope = {{0.1, 0.1}};
  c = m.correct(middle());
  EXPECT_EQ(c.message.find("outside the envelope: the AWCC forest's velocity median"), 0u) << c.message;
  EXPECT_EQ(c.message.find("outside the envelope", 1), std::string::npos) << c.message;
  EXPECT_NE(c.message.find("; the AWCC forest's Tu median"), std::string::npos) << c.message;
}

TEST(TrustRules, EnvelopeOfShiftsTakesTheConformalRankAndHoldsTheMeasurement) {
  // At 99 %: 199 shifts -99..99, k = ceil(200 x 0.995) = 199, the extremes.
  std::vector<double> s;
  for (int i = -99; i <= 99; ++i) s.push_back(i);
  auto e = correction::envelope_of(s, 0.99);
  ASSERT_TRUE(e);
  EXPECT_EQ((*e)[0], 99.0);
  EXPECT_EQ((*e)[1], 99.0);
  s.pop_back();  // 198: the rank is beyond the runs
  EXPECT_FALSE(correction::envelope_of(s, 0.99));
  // The rule's own 99.5 %: 399 runs at least (k = ceil(400 x 0.9975) = 399).
  s.clear();
  for (int i = 1; i <= 398; ++i) s.push_back(i);
  EXPECT_FALSE(correction::envelope_of(s));
  s.push_back(399);
  e = correction::envelope_of(s);
  ASSERT_TRUE(e);
  EXPECT_EQ((*e)[1], 399.0);
  // Every shift above 0: the lower end (the 399th largest, 1) is above 0,
  // and the envelope holds the measurement instead.
  EXPECT_EQ((*e)[0], 0.0);
  // 799 shifts 1..799 at 99.5 %: k = ceil(800 x 0.9975) = 798.
  s.clear();
  for (int i = 1; i <= 799; ++i) s.push_back(i);
  EXPECT_EQ((*correction::envelope_of(s))[1], 798.0);
  // Brute force: of random shifts, at most 0.25 % + 1 lie beyond each end.
  std::mt19937_64 g(1);
  std::normal_distribution<double> n(0.0, 1.0);
  s.clear();
  for (int i = 0; i < 2000; ++i) s.push_back(n(g));
  e = correction::envelope_of(s);
  ASSERT_TRUE(e);
  EXPECT_LE(std::count_if(s.begin(), s.end(), [&](double x) { return x > (*e)[1]; }), 5);
  EXPECT_LE(std::count_if(s.begin(), s.end(), [&](double x) { return x < -(*e)[0]; }), 5);
  EXPECT_GE(std::count_if(s.begin(), s.end(), [&](double x) { return x >= (*e)[1]; }), 5);
}

TEST(TrustRules, AModelWithoutEnvelopesTakesItsTrainingTargetsAndPerGroupEnvelopesRoundTrip) {
  // Too few training targets for the rank (399): no envelope at all.
  EXPECT_TRUE(model_of([](int) { return 1.0; }, [](int) { return 0.0; }).calibration.velocity_envelope.empty());
  auto m = model_of([](int i) { return 0.5 + i / 500.0; }, [](int i) { return -0.1 + i / 2500.0; }, 500);
  // From the training targets: shifts t - 1 for the ratio, t for the difference.
  auto shifts = m.velocity.targets();
  ASSERT_FALSE(m.calibration.velocity_envelope.empty());
  for (double& t : shifts) t -= 1.0;
  ASSERT_TRUE(m.calibration.envelope_from_training);
  EXPECT_EQ(m.calibration.velocity_envelope.front(), *correction::envelope_of(shifts));
  EXPECT_EQ(m.calibration.turbulence_envelope.front(), *correction::envelope_of(m.turbulence_intensity.targets()));
  // Not stored: a reader takes them again from the same targets.
  auto back = CorrectionModel::parse(m.serialise(), "mem");
  EXPECT_TRUE(back.calibration.envelope_from_training);
  EXPECT_EQ(back.calibration.velocity_envelope, m.calibration.velocity_envelope);
  // Per group (two window bands, two Tu bands): stored and read back as they are.
  auto& c = m.calibration;
  c.window_edges = {30};
  c.tu_edges = {0.2};
  c.velocity.assign(4, {0.0, 0.0, 0.0});
  c.turbulence_intensity.assign(4, {0.0, 0.0, 0.0});
  c.velocity_envelope = {{0.1, 0.2}, {0.3, 0.4}, {0.5, 0.6}, {0.7, 0.8}};
  c.turbulence_envelope = {{0.01, 0.02}, {0.03, 0.04}, {0.05, 0.06}, {0.07, 0.08}};
  c.envelope_from_training = false;
  const auto bytes = m.serialise();
  back = CorrectionModel::parse(bytes, "mem");
  EXPECT_FALSE(back.calibration.envelope_from_training);
  EXPECT_EQ(back.calibration.velocity_envelope, c.velocity_envelope);
  EXPECT_EQ(back.calibration.turbulence_envelope, c.turbulence_envelope);
  EXPECT_EQ(back.serialise(), bytes);
  // A row's group: windows 100 is band 1, the Tu median 0.25 band 1; unknown windows take the widest.
  EXPECT_EQ(*c.envelope(c.velocity_envelope, 100, 0.25), (std::array<double, 2>{0.7, 0.8}));
  EXPECT_EQ(*c.envelope(c.velocity_envelope, -1, 0.1), (std::array<double, 2>{0.5, 0.6}));
  EXPECT_EQ(c.group_text(100, 0.25), "windows 30+, model Tu 0.2+");
  EXPECT_EQ(c.group_text(12, 0.1), "windows up to 29, model Tu below 0.2");
}

TEST(TrustRules, AMultimodalDistributionIsUntrustedWithItsQuantilesKept) {
  // Half the runs truth = 0.9-1.1 x AWCC, half 2.7-3.3 x, and nothing in the
  // features to tell them apart: the forest's median is a coin's toss.
  const auto m = model_of([](int i) { return i % 2 ? 2.7 + 0.6 * i / 300.0 : 0.9 + 0.2 * i / 300.0; },
                          [](int) { return 0.0; });
  const auto c = m.correct(middle());
  EXPECT_EQ(c.status, CorrectionStatus::untrusted);
  EXPECT_TRUE(c.multimodal);
  EXPECT_FALSE(c.outside_envelope);  // the truths moved by -10 to +230 %: the median's move is inside
  EXPECT_NE(c.message.find("multimodal: the AWCC forest's velocity distribution is"), std::string::npos) << c.message;
  ASSERT_TRUE(c.velocity);
  EXPECT_LT(c.velocity->quantiles[1], 2.3);
  EXPECT_GT(c.velocity->quantiles[5], 5.3);
  // One mode with the same spread of targets is corrected.
  const auto one = model_of([](int i) { return 0.9 + 2.4 * i / 299.0; }, [](int) { return 0.0; });
  EXPECT_TRUE(one.correct(middle()).corrected()) << one.correct(middle()).message;
}

TEST(TrustRules, ALagOfOneSampleIsUntrustedBelowTheLimitAndWithoutFsIsNotJudged) {
  // Rule (c): the lag in samples dx fs / u. Every target 1.0 (the forest
  // returns the measurement), so rules (a) and (b) hold and only the lag
  // decides. u 2 m/s, dx 0.5 m: fs 6 Hz is a lag of exactly 1.5 samples.
  const auto m = model_of([](int) { return 1.0; }, [](int) { return 0.0; });
  auto f = middle();
  ASSERT_TRUE(m.correct(f).corrected()) << "fs not known (a peer's row): not judged";
  f.fs = 6.0;
  EXPECT_TRUE(m.correct(f).corrected()) << m.correct(f).message;
  f.fs = std::nextafter(6.0, 0.0);
  auto c = m.correct(f);
  EXPECT_EQ(c.status, CorrectionStatus::untrusted);
  EXPECT_TRUE(c.one_sample_lag);
  EXPECT_FALSE(c.outside_envelope);
  EXPECT_FALSE(c.multimodal);
  // At one sample (fs 4 Hz: dx fs = 2 m/s) the bounds are 2 / 1.5 and 2 / 0.5.
  f.fs = 4.0;
  c = m.correct(f);
  EXPECT_EQ(c.message.find("a lag of one sample: AWCC's velocity 2 m/s is a lag of 1.00 samples (dx fs / u, below 1.5)"),
            0u)
      << c.message;
  EXPECT_NE(c.message.find("so the record bounds the velocity (1.333-4 m/s)"), std::string::npos) << c.message;
  EXPECT_EQ(c.why_not(), "untrusted: " + c.message);
  ASSERT_TRUE(c.velocity);  // the quantiles kept, as for the other rules
  EXPECT_DOUBLE_EQ(c.velocity->median(), 2.0);
  EXPECT_TRUE(correction::to_json(c)["velocity"]["median"].is_null());
}

TEST(TrustRules, AYieldBelowChanceIsUntrustedAtTheLimitItIsNotAndUnknownWindowsAreNotJudged) {
  // Rule (d): accepted / formed windows below 0.1 %. Targets 1.0, so rules
  // (a) and (b) hold; no fs, so rule (c) is silent.
  const auto m = model_of([](int) { return 1.0; }, [](int) { return 0.0; });
  auto f = middle();
  f.windows_accepted = 10;
  f.windows_total = -1;
  EXPECT_TRUE(m.correct(f).corrected()) << "windows formed not known: not judged";
  f.windows_total = 10'000;  // 0.1 % exactly
  EXPECT_TRUE(m.correct(f).corrected()) << m.correct(f).message;
  f.windows_total = 10'001;
  const auto c = m.correct(f);
  EXPECT_EQ(c.status, CorrectionStatus::untrusted);
  EXPECT_TRUE(c.chance_yield);
  EXPECT_FALSE(c.one_sample_lag || c.outside_envelope || c.multimodal);
  EXPECT_EQ(c.message.find("a chance yield: AWCC accepted 10 of 10001 windows (0.1 %, below 0.1 %)"), 0u) << c.message;
  ASSERT_TRUE(c.velocity);
  EXPECT_DOUBLE_EQ(c.velocity->median(), 2.0);  // the quantiles kept
}

TEST(TrustRules, TuOfBubblesFarLargerThanTheTipSeparationIsNotCorrectedAboveTheLimitAndTheVelocityStands) {
  // Rule (e): d32 / dx above 10 holds back Tu's median, not the velocity's.
  // Targets 1.0 and 0.0 (the forest returns the measurement), so rules
  // (a)-(d) hold and only the ratio decides. dx 0.5 m: d32 5 m is 10 exactly.
  const auto m = model_of([](int) { return 1.0; }, [](int) { return 0.0; });
  auto f = middle();
  f.d32 = 5.0;
  auto c = m.correct(f);
  EXPECT_TRUE(c.turbulence_corrected()) << c.turbulence_message;
  EXPECT_FALSE(c.large_bubbles);
  EXPECT_TRUE(c.turbulence_message.empty());
  f.d32 = std::nextafter(5.0, 10.0);
  c = m.correct(f);
  EXPECT_TRUE(c.corrected()) << c.message;
  EXPECT_TRUE(c.large_bubbles);
  EXPECT_FALSE(c.turbulence_corrected());
  EXPECT_FALSE(c.outside_envelope || c.multimodal || c.one_sample_lag || c.chance_yield);
  EXPECT_EQ(c.turbulence_message.find("Tu not corrected: the Sauter diameter d32 5000 mm is 10 times the tip "
                                      "separation dx 500 mm (above 10)"),
            0u)
      << c.turbulence_message;
  ASSERT_TRUE(c.velocity && c.turbulence_intensity);
  EXPECT_DOUBLE_EQ(c.turbulence_intensity->median(), 0.2);  // the quantiles kept
  // JSON: the velocity's median stands, Tu's is null with the reason.
  const auto j = correction::to_json(c);
  EXPECT_EQ(j["status"], "corrected");
  EXPECT_DOUBLE_EQ(j["velocity"]["median"].get<double>(), 2.0);
  EXPECT_TRUE(j["velocity"].find("reason") == j["velocity"].end());
  EXPECT_TRUE(j["turbulence_intensity"]["median"].is_null());
  EXPECT_DOUBLE_EQ(j["turbulence_intensity"]["quantiles"]["0.5"].get<double>(), 0.2);
  EXPECT_EQ(j["turbulence_intensity"]["reason"].get<std::string>(), c.turbulence_message);
  // CSV: the same, the reason in its column.
  auto cell = csv_cells_by_column(c);
  ASSERT_EQ(cell.size(), correction::correction_csv_columns().size());
  EXPECT_EQ(cell["corrected_velocity"], "2");
  EXPECT_EQ(cell["corrected_turbulence_intensity"], "");
  EXPECT_EQ(cell["corrected_turbulence_intensity_q0.5"], "0.2");
  EXPECT_EQ(cell[std::string(correction::correction_column::turbulence_reason)], c.turbulence_message);
  // A corrected Tu has a null reason; a row without d32 (0: not known) or dx is not judged.
  EXPECT_TRUE(correction::to_json(m.correct(middle()))["turbulence_intensity"]["reason"].is_null());
  f.dx = 0.0;
  EXPECT_FALSE(m.correct(f).large_bubbles);
  f = middle();
  f.d32 = 0.0;
  EXPECT_FALSE(m.correct(f).large_bubbles);
  // An untrusted row is judged too: its Tu reason is given beside the row's.
  f = middle();
  f.d32 = 6.0;
  f.fs = 4.0;  // rule (c)
  c = m.correct(f);
  EXPECT_EQ(c.status, CorrectionStatus::untrusted);
  EXPECT_TRUE(c.one_sample_lag && c.large_bubbles);
  EXPECT_EQ(c.message.find("a lag of one sample"), 0u) << c.message;
}

// A row as pdp process measures it: AWCC's u (m/s) and Tu, the leading
// tip's c and F (1/s), dx (m), AWCC's {accepted, formed} windows, the
// record's {fs (Hz), duration (s)}, FSCC's {u (m/s), R12max}; Np 10, dy 0,
// a time-scale ratio T_u / T_W of 2 (inside the shipped model's range).
correction::Measurement row(double u, double tu, double c, double rate, double dx, std::array<std::int64_t, 2> windows,
                            std::array<double, 2> record, std::array<double, 2> fscc) {
  correction::Measurement m;
  m.velocity = u;
  m.turbulence_intensity = tu;
  m.void_fraction = c;
  m.bubble_count_rate = rate;
  m.dx = dx;
  m.np = 10;
  m.windows_accepted = windows[0];
  m.windows_total = windows[1];
  m.fs = record[0];
  m.duration = record[1];
  m.fscc_velocity = fscc[0];
  m.r12_max = fscc[1];
  m.weighting = awcc::Weighting::duration;  // pdp process's default, which it states
  m.time_scale_ratio = 2.0;
  return m;
}

TEST(TrustRules, TheTwoMillimetreRowOfTheRealProfileIsCorrectedWithOneMode) {
  // Issue 29, case 1, and issue 33: file dc157_01 (y = 2 mm: c 0.004, 2 of 72
  // AWCC windows, FSCC 2.80 m/s with R12max 0.041, 45 s at 20 kHz) was
  // corrected by the FSCC forest to 6.62 m/s (95 % 2.37-13.1, two modes),
  // then flagged untrusted; with the logarithmic range margin the model of
  // issue 29 refused it (its FSCC forest's least c was 0.0041). The cause
  // was the training: the forest had no runs at c below 0.004 at 20 kHz, and
  // its leaves mixed rows whose FSCC lag was quantised
  // (docs/history/correction-foreign-conventions.md, "The FSCC forest at
  // low void fraction: fixed by the campaign's prior").
  // The model trained on the conventions campaign (c from 0.002) corrects it
  // with one mode around FSCC's own value: at c = 0.004 a bubble crosses
  // both tips alone, so FSCC's peak is the lag of single bubbles (the
  // interim models of the sparse sweeps gave 2.75-2.78 m/s).
  const auto m = CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  const auto r = row(1.17, 0.84, 0.0036577777777777776, 16.133333333333333, 7.15e-3, {2, 72}, {20e3, 45.0},
                     {2.803921568627451, 0.04131864076587361});
  ASSERT_TRUE(m.fscc.has_value());
  const auto& c_range = *std::find_if(m.fscc->ranges.begin(), m.fscc->ranges.end(),
                                      [](const auto& fr) { return fr.name == "void_fraction"; });
  EXPECT_LT(c_range.min, 0.003);  // trained below the row's c, not only at its edge
  const auto c = m.correct(r);
  ASSERT_EQ(c.status, CorrectionStatus::corrected) << c.message;
  EXPECT_EQ(c.forest, "fscc");
  EXPECT_FALSE(c.multimodal);
  ASSERT_TRUE(c.velocity);
  // Within 10 % of FSCC's 2.80 m/s, and a 50 % interval under 0.5 m/s wide
  // (the bimodal answer's was 2.84-10.1).
  EXPECT_NEAR(c.velocity->median(), 2.80, 0.28);
  EXPECT_LT(c.velocity->quantiles[4] - c.velocity->quantiles[2], 0.5);
  EXPECT_FALSE(c.turbulence_intensity);  // the FSCC forest corrects the velocity only
}

TEST(LongRecords, DurationBeyondTheRangeIsHeldAtItsEndWithANote) {
  // Issue 29, case 6: a 30-minute record against the shipped model's
  // 20-300 s was refused ("duration = 1800 is outside the training range
  // [20.0007, 299.802]", "FSCC forest:" twice).
  const auto m = CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  const auto& range = *std::find_if(m.ranges.begin(), m.ranges.end(), [](const auto& r) { return r.name == "duration"; });
  // The base scene at 3 m/s and Tu 0.30 for 30 minutes at 500 kHz, as pdp process measures it.
  auto f = correction::make_features(row(3.34, 0.207, 0.273, 376.4, 5e-3, {10042, 67751}, {500e3, 1800.0}, {3.29, 0.17}))
               .features;
  f.dy = 1e-3;
  const auto c = m.correct(f);
  ASSERT_TRUE(c.corrected()) << c.message;
  ASSERT_EQ(c.notes.size(), 1u) << fmt::format("{}", fmt::join(c.notes, " | "));
  EXPECT_EQ(c.notes[0], fmt::format("duration 1800 s is beyond the training range ({:.4g}-{:.4g} s): corrected as "
                                    "{:.4g} s",
                                    range.min, range.max, range.max));
  // The shipped model (issue 33) was trained on records to 1,800 s; its
  // forests hold every record beyond the longest 1 % of them at that length.
  EXPECT_EQ(c.notes[0], "duration 1800 s is beyond the training range (20-932.2 s): corrected as 932.2 s");
  // The same quantiles as a record of exactly the longest training length, which has no note.
  f.duration = range.max;
  const auto held = m.correct(f);
  ASSERT_TRUE(held.corrected());
  EXPECT_TRUE(held.notes.empty());
  EXPECT_EQ(c.velocity->quantiles, held.velocity->quantiles);
  EXPECT_EQ(c.turbulence_intensity->quantiles, held.turbulence_intensity->quantiles);
  // In the JSON and the CSV, once each.
  const auto j = correction::to_json(c);
  EXPECT_EQ(j["notes"].size(), 1u);
  EXPECT_EQ(correction::notes_text(c), c.notes[0]);
  // A shorter record than the shortest is refused, in units, saying why.
  f.duration = 5.0;
  const auto short_one = m.correct(f);
  EXPECT_EQ(short_one.status, CorrectionStatus::outside_training_range);
  EXPECT_EQ(short_one.message,
            fmt::format("duration = 5 s is outside the training range {:.4g}-{:.4g} s: a shorter record holds less than "
                        "any the model learnt from",
                        range.min, range.max));
  // No other feature is held: a rate above the range stays refused.
  f.duration = 1800.0;
  f.fs = 5e6;
  const auto fast = m.correct(f);
  EXPECT_EQ(fast.status, CorrectionStatus::outside_training_range);
  EXPECT_NE(fast.message.find("fs = 5000 kHz is outside the training range 10-999.9 kHz"), std::string::npos)
      << fast.message;
  EXPECT_TRUE(fast.notes.empty());
}

TEST(LongRecords, TheFsccForestHoldsTheDurationToo) {
  const auto m = CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  // 5 windows: too few for the AWCC forest; FSCC's velocity goes to the FSCC forest.
  const auto r = row(2.4, 0.2, 0.02, 40.0, 5e-3, {5, 200}, {100e3, 1800.0}, {2.5, 0.3});
  const auto c = m.correct(r);
  ASSERT_TRUE(c.velocity) << c.message;
  EXPECT_EQ(c.forest, "fscc");
  // Why not the AWCC forest, then the FSCC forest's own note.
  ASSERT_EQ(c.notes.size(), 2u);
  EXPECT_EQ(c.notes[0], "AWCC forest: 5 accepted windows; the model was trained on runs with at least 10; corrected "
                        "from FSCC's velocity by the FSCC forest, which gives no Tu");
  EXPECT_NE(c.notes[1].find("duration 1800 s is beyond the training range"), std::string::npos);
}

// The lag in samples, dx fs / u, is a feature of the AWCC forest (not of the
// FSCC forest): a row whose lag lies outside its training range, with every
// other feature inside, is refused by the AWCC forest by name and in
// samples, and corrected from FSCC's velocity by the FSCC forest, which says
// so. Below the range: dx typed as 0.6 mm for 6 mm at 20 kHz and 20 m/s (0.6
// samples; a real AWCC lag is at least one). Above it: 1 m/s past tips 9.9 mm
// apart sampled at 990 kHz (9,801 samples).
TEST(Messages, ALagOutsideTheAwccForestsRangeIsNamedInSamples) {
  const auto m = CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  const auto& lag = *std::find_if(m.ranges.begin(), m.ranges.end(), [](const auto& x) { return x.name == "lag_samples"; });
  struct Case {
    double u, dx, fs, lag;
  };
  for (const Case k : {Case{20.0, 0.6e-3, 20e3, 0.6}, Case{1.0, 9.9e-3, 990e3, 9801.0}}) {
    auto r = row(k.u, 0.2, 0.2, 300.0, k.dx, {500, 1000}, {k.fs, 100.0}, {k.u, 0.3});
    r.dy = 1e-3;
    // Every other feature of the AWCC forest is inside its range.
    const auto features = correction::make_features(r).features;
    for (const auto& range : m.ranges) {
      const auto v = features.value(range.name);
      if (range.name == "lag_samples" || !v) continue;
      EXPECT_TRUE(*v >= range.min && *v <= range.max) << range.name << " = " << *v;
    }
    ASSERT_NEAR(*features.value("lag_samples"), k.lag, 1e-9 * k.lag);
    const auto c = m.correct(r);
    // FSCC's velocity at 0.6 samples is no measurement either (trust rule
    // (c)): its quantiles stay, untrusted, with the same note.
    EXPECT_EQ(c.status, k.lag < 1.5 ? CorrectionStatus::untrusted : CorrectionStatus::corrected) << c.message;
    EXPECT_EQ(c.one_sample_lag, k.lag < 1.5) << c.message;
    EXPECT_EQ(c.forest, "fscc");
    ASSERT_FALSE(c.notes.empty());
    EXPECT_EQ(c.notes[0], fmt::format("AWCC forest: lag_samples = {} samples is outside the training range {}; "
                                      "corrected from FSCC's velocity by the FSCC forest, which gives no Tu",
                                      k.lag, correction::feature_range_text("lag_samples", lag.min, lag.max)))
        << c.notes[0];
  }
}

TEST(Messages, AFeatureBothForestsRefuseIsNamedOnceWithUnits) {
  // Droplet flow: c outside both forests' ranges. Each was said in full,
  // the second time after "FSCC forest:".
  const auto m = CorrectionModel::load(pdp_test::source_dir() / "samples" / "model" / "awcc.qrf");
  auto r = row(2.4, 0.2, 0.9, 100.0, 5e-3, {500, 1000}, {100e3, 100.0}, {2.5, 0.3});
  const auto c = m.correct(r);
  EXPECT_EQ(c.status, CorrectionStatus::outside_training_range);
  const auto& a = *std::find_if(m.ranges.begin(), m.ranges.end(), [](const auto& x) { return x.name == "void_fraction"; });
  const auto& b =
      *std::find_if(m.fscc->ranges.begin(), m.fscc->ranges.end(), [](const auto& x) { return x.name == "void_fraction"; });
  EXPECT_EQ(c.message, fmt::format("void_fraction = 0.9 is outside the training ranges of both forests (AWCC forest "
                                   "{:.4g}-{:.4g}, FSCC forest {:.4g}-{:.4g}): above c = 0.5 the flow is droplets in "
                                   "air, which this model was not trained on (its campaigns stop at c = 0.6; the "
                                   "synthetic probe models the spray region since issue 31)",
                                   a.min, a.max, b.min, b.max));
  EXPECT_EQ(c.message.find("FSCC forest:"), std::string::npos);
  // Different reasons are both given, the FSCC forest's named once.
  r.void_fraction = 0.3;
  r.windows_accepted = 3;  // AWCC forest: too few windows
  r.dx = 0.05;             // FSCC forest: dx outside its range
  const auto d = m.correct(r);
  EXPECT_EQ(d.status, CorrectionStatus::too_few_windows);
  const auto at = d.message.find("; FSCC forest: dx = 50 mm is outside the training range");
  EXPECT_NE(at, std::string::npos) << d.message;
  EXPECT_EQ(d.message.find("FSCC forest:", at + 3), std::string::npos) << d.message;
}

}  // namespace

namespace {

TEST(TrustRules, EnvelopesMeasuredOnFreshRunsReplaceTheTrainingTargets) {
  // pdp train --envelope-of: a model whose forests move u by +20 % and Tu by
  // +0.05 everywhere, measured on 1,000 runs whose truths lie 10 % and 0.02
  // above the measurement: the envelope is [0, +10 %] and [0, +0.02] (every
  // truth's shift the same), and every held-out row breaks it.
  const auto model = model_of([](int) { return 1.2; }, [](int) { return 0.05; });
  ASSERT_TRUE(model.calibration.velocity_envelope.empty());  // 300 targets: too few for the rank
  correction::TrainingSet set;
  std::mt19937_64 g(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    correction::TrainingRow r;
    r.study = 1;
    r.run = i;
    r.features = middle();
    r.features.velocity = 1.0 + u(g);
    r.features.turbulence_intensity = 0.1 + 0.2 * u(g);
    r.true_velocity = 1.1 * r.features.velocity;
    r.true_turbulence_intensity = r.features.turbulence_intensity + 0.02;
    set.rows.push_back(r);
  }
  correction::TrainOptions o;
  o.held_out = 0.2;
  const auto t = correction::measure_trust(model, set, o);
  EXPECT_EQ(t.envelope_rows, 800);
  const auto& c = t.model.calibration;
  EXPECT_FALSE(c.envelope_from_training);
  ASSERT_EQ(c.velocity_envelope.size(), 1u);
  EXPECT_EQ(c.velocity_envelope[0][0], 0.0);
  EXPECT_NEAR(c.velocity_envelope[0][1], 0.1, 1e-12);
  EXPECT_NEAR(c.turbulence_envelope[0][1], 0.02, 1e-12);
  EXPECT_EQ(t.held_out.rows, 200);
  EXPECT_EQ(t.held_out.untrusted, 200);
  EXPECT_EQ(t.held_out.outside_envelope, 200);
  EXPECT_NE(t.model.provenance.find("Trust envelopes (rule (a), model.hpp) measured by pdp train"), std::string::npos);
  // Stored (format 5) and read back as measured.
  const auto back = CorrectionModel::parse(t.model.serialise(), "mem");
  EXPECT_EQ(back.calibration.velocity_envelope, c.velocity_envelope);
  EXPECT_FALSE(back.calibration.envelope_from_training);
  // Runs processed otherwise are refused.
  set.processing.filter_a = 0.3;
  EXPECT_THROW(correction::measure_trust(model, set, o), awcc::InputError);
}

}  // namespace
