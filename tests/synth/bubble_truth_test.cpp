#include "synth/bubble_truth.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <thread>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/interface_times.hpp"
#include "synth/sidecar.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

using synth::BubbleTruth;
using synth::Scene;
using synth::Synthesis;
using synth::SynthesisOptions;
using synth::TipPierce;
using synth::Vec3;

Synthesis run_truth(const Scene& s, bool bubble_truth = true, bool reference = false, std::int64_t chunk = 1 << 16) {
  SynthesisOptions o;
  o.bubble_truth = bubble_truth;
  o.keep_reference_data = reference;
  o.chunk_steps = chunk;
  return synth::synthesise(s, o);
}

const std::vector<Vec3> kFourTips = {{0, 0, 0}, {5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {5e-3, 0, 1.5e-3}};

// Straight paths: no turbulence, so every bubble moves at (u, 0, 0) and its
// passage through a tip is a ray through a sphere.
Scene straight_scene() {
  Scene s;
  s.velocity = 2.0;
  s.tu = s.tu_y = s.tu_z = 0.0;
  s.void_fraction = 0.05;
  s.bubble_diameter = 4e-3;
  s.tips = kFourTips;
  s.fs = 100e3;
  s.duration = 2.0;
  return s;
}

// A turbulent four-tip scene whose flow reverses (bubbles pass tips twice),
// with ellipsoids of several sizes: every path of the table's code.
Scene turbulent_scene() {
  Scene s;
  const std::pair<const char*, const char*> fields[] = {
      {"velocity", "1m/s"},      {"tu", "0.7"},      {"tu-y", "0.2"},         {"tu-z", "0.2"},
      {"time-scale", "2ms"},     {"duration", "3s"}, {"fs", "50kHz"},         {"bubble-diameter", "2mm"},
      {"diameter-log-sd", "0.3"}, {"aspect-ratio", "0.7"}, {"tips", "0,0,0;2mm,0,0;2mm,0.8mm,0;2mm,0,0.8mm"}};
  for (const auto& [name, value] : fields) synth::set_scene_field(s, name, value);
  return s;
}

// Table rows piercing tip k, in the order of their front interface.
std::vector<std::size_t> rows_at(const BubbleTruth& t, std::size_t k) {
  std::vector<std::size_t> rows;
  for (std::size_t r = 0; r < t.size(); ++r)
    if (t.pierce(r, k).pierced()) rows.push_back(r);
  std::sort(rows.begin(), rows.end(), [&](std::size_t a, std::size_t b) { return t.pierce(a, k).front < t.pierce(b, k).front; });
  return rows;
}

// The sampled recording against the table, tip by tip (for a scene whose
// flow never reverses: the table lists a bubble's first pass only). Sample n
// is air when n / fs lies inside a passage; passages whose samples touch
// (bubbles closer than a sample apart) make one air interval. Each interval's
// interfaces, timed half way between the straddling samples
// (awcc/interface_times.hpp), lie within half a sample of the true ones: the
// true front lies between the last water sample and the first air sample.
// A passage that holds no sample time leaves no interval.
void expect_recording_matches_table(const Synthesis& out, const Scene& s) {
  const BubbleTruth& t = *out.bubbles;
  for (std::size_t r = 0; r < t.size(); ++r) ASSERT_EQ(t.extra_passes[r], 0) << "the flow must not reverse";
  const double half = 0.5 / s.fs + 1e-12;
  const auto samples = static_cast<double>(s.sample_count());
  for (std::size_t k = 0; k < out.signals.size(); ++k) {
    struct Expected {
      double first, stop, front, rear;  // samples [first, stop); true times (rear NaN: censored)
    };
    std::vector<Expected> expected;
    for (const std::size_t r : rows_at(t, k)) {
      const TipPierce& p = t.pierce(r, k);
      const double first = std::max(0.0, std::floor(p.front * s.fs) + 1.0);
      const double stop = p.censored() ? samples : std::min(samples, std::ceil(p.rear * s.fs));
      if (first >= stop) continue;
      if (!expected.empty() && first <= expected.back().stop) {
        expected.back().stop = std::max(expected.back().stop, stop);
        expected.back().rear = p.rear;
        continue;
      }
      expected.push_back({first, stop, p.front, p.rear});
    }
    const auto crossings = awcc::crossings(out.signals[k]);
    ASSERT_EQ(crossings.size(), expected.size()) << "tip " << k;
    ASSERT_GT(crossings.size(), 10u) << "tip " << k;
    for (std::size_t c = 0; c < crossings.size(); ++c) {
      if (expected[c].front > 0.0) {
        EXPECT_NEAR(crossings[c].front, expected[c].front, half) << "tip " << k;
      }
      if (!std::isnan(expected[c].rear)) {
        EXPECT_NEAR(crossings[c].rear, expected[c].rear, half) << "tip " << k;
      }
    }
  }
}

// Rows per tip and per pair against the counts the truth has always given.
void expect_counts_match(const Synthesis& out) {
  const BubbleTruth& t = *out.bubbles;
  ASSERT_EQ(t.tip_count, out.truth.tips.size());
  for (std::size_t k = 0; k < t.tip_count; ++k) {
    EXPECT_EQ(static_cast<std::int64_t>(rows_at(t, k).size()), out.truth.tips[k].bubbles_pierced) << "tip " << k;
  }
  for (const auto& pair : out.truth.pairs) {
    std::int64_t both = 0;
    for (std::size_t r = 0; r < t.size(); ++r)
      both += t.pierce(r, static_cast<std::size_t>(pair.first)).pierced() &&
              t.pierce(r, static_cast<std::size_t>(pair.second)).pierced();
    EXPECT_EQ(both, pair.pierced_by_both) << "tips " << pair.first << ", " << pair.second;
  }
  // Every row pierced some tip, ids are distinct and ascending.
  for (std::size_t r = 0; r < t.size(); ++r) {
    bool any = false;
    for (std::size_t k = 0; k < t.tip_count; ++k) any = any || t.pierce(r, k).pierced();
    EXPECT_TRUE(any) << "row " << r;
    if (r > 0) {
      EXPECT_LT(t.id[r - 1], t.id[r]);
    }
  }
}

TEST(BubbleTruth, StraightPathsMatchRaySphereIntersections) {
  const Scene s = straight_scene();
  const Synthesis out = run_truth(s, true, true);
  ASSERT_TRUE(out.bubbles && out.reference);
  const auto& ref = *out.reference;
  for (const auto& u : ref.velocities) ASSERT_TRUE(u == (Vec3{s.velocity, 0.0, 0.0})) << "the path must be straight";
  const BubbleTruth& t = *out.bubbles;
  const double R = 0.5 * s.bubble_diameter;
  const double U = s.velocity;

  // Bubble k's centre at time t is entry + D(t) - key, D(t) = U (t - t_start)
  // along x. Tip p is inside when (p_x - c_x)^2 + rho^2 < R^2: with
  // h = sqrt(R^2 - rho^2) the centre is at p_x - h at the front and p_x + h
  // at the rear, the chord is 2 h, and the outward normal at the pierce
  // point is (p - c) / R = (+-h, p_y - e_y, p_z - e_z) / R.
  std::size_t expected_rows = 0, checked = 0;
  std::size_t row = 0;
  for (std::size_t id = 0; id < ref.bubbles.size(); ++id) {
    const auto& b = ref.bubbles[id];
    bool in_record = false;
    std::vector<TipPierce> want(ref.tips.size());
    for (std::size_t k = 0; k < ref.tips.size(); ++k) {
      const Vec3& p = ref.tips[k];
      const double dy = p.y - b.entry.y, dz = p.z - b.entry.z;
      const double rho2 = dy * dy + dz * dz;
      if (rho2 >= R * R) continue;
      const double h = std::sqrt(R * R - rho2);
      const double front = ref.t_start + (p.x - h - b.entry.x + b.key.x) / U;
      const double rear = ref.t_start + (p.x + h - b.entry.x + b.key.x) / U;
      if (rear <= 0.0 || front >= s.duration) continue;
      in_record = true;
      want[k].front = front;
      want[k].rear = rear < s.duration ? rear : TipPierce::none;
      want[k].chord = rear < s.duration ? 2.0 * h : TipPierce::none;
      want[k].front_normal = {static_cast<float>(h / R), static_cast<float>(dy / R), static_cast<float>(dz / R)};
      want[k].rear_normal = {static_cast<float>(-h / R), static_cast<float>(dy / R), static_cast<float>(dz / R)};
    }
    if (!in_record) continue;
    ++expected_rows;
    ASSERT_LT(row, t.size()) << "bubble " << id << " is missing from the table";
    ASSERT_EQ(t.id[row], id) << "the table lacks bubble " << id << " or has one that pierced nothing";
    EXPECT_DOUBLE_EQ(t.diameter[row], s.bubble_diameter);
    EXPECT_TRUE(t.semi_axes[row] == (Vec3{R, R, R}));
    // (D(end) - D(start)) / span: D ~ U t is a few metres, so rounding
    // leaves ~1e-16 D / span ~ 1e-12 of U.
    EXPECT_NEAR(t.velocity[row].x, U, 1e-10 * U);
    EXPECT_EQ(t.velocity[row].y, 0.0);
    EXPECT_EQ(t.velocity[row].z, 0.0);
    EXPECT_EQ(t.extra_passes[row], 0);
    double first = 1e300, last = -1e300;
    for (std::size_t k = 0; k < ref.tips.size(); ++k) {
      const TipPierce& got = t.pierce(row, k);
      const TipPierce& w = want[k];
      ASSERT_EQ(got.pierced(), w.pierced()) << "bubble " << id << " tip " << k;
      if (!w.pierced()) continue;
      ++checked;
      first = std::min(first, w.front);
      last = std::max(last, std::isnan(w.rear) ? w.front : w.rear);
      EXPECT_NEAR(got.front, w.front, 1e-10) << "bubble " << id << " tip " << k;
      EXPECT_EQ(got.censored(), w.censored());
      if (!w.censored()) {
        EXPECT_NEAR(got.rear, w.rear, 1e-10) << "bubble " << id << " tip " << k;
        EXPECT_NEAR(got.chord, w.chord, 1e-9 * R) << "bubble " << id << " tip " << k;
      }
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(got.front_normal[i], w.front_normal[i], 2e-6) << "bubble " << id << " tip " << k;
        if (!w.censored()) {
          EXPECT_NEAR(got.rear_normal[i], w.rear_normal[i], 2e-6) << "bubble " << id << " tip " << k;
        }
      }
    }
    EXPECT_NEAR(t.interaction_start[row], first, 1e-10);
    EXPECT_NEAR(t.interaction_end[row], last, 1e-10);
    ++row;
  }
  EXPECT_EQ(t.size(), expected_rows) << "rows for bubbles that pierced no tip in the record";
  EXPECT_GT(checked, 200u) << "the scene must pierce enough bubbles to mean something";
  expect_counts_match(out);
  expect_recording_matches_table(out, s);
}

// Minimum image on the periodic cross-section (as the synthesiser places
// bubbles), computed independently.
double periodic(double x, double length) { return x - length * std::nearbyint(x / length); }

TEST(BubbleTruth, TurbulentPathsGiveSurfacePointsNormalsAndTheInteractionMeanVelocity) {
  const Scene s = turbulent_scene();
  const Synthesis out = run_truth(s, true, true);
  ASSERT_TRUE(out.bubbles && out.reference);
  const auto& ref = *out.reference;
  const BubbleTruth& t = *out.bubbles;

  // D(t) by summing the step velocities: the independent reference.
  std::vector<Vec3> d(ref.velocities.size() + 1);
  for (std::size_t k = 0; k < ref.velocities.size(); ++k) {
    const Vec3& u = ref.velocities[k];
    d[k + 1] = {d[k].x + u.x * ref.step, d[k].y + u.y * ref.step, d[k].z + u.z * ref.step};
  }
  auto displacement = [&](double time) {
    auto k = static_cast<std::size_t>(std::floor((time - ref.t_start) / ref.step));
    k = std::min(k, ref.velocities.size() - 1);
    const double s_in = time - (ref.t_start + static_cast<double>(k) * ref.step);
    const Vec3& u = ref.velocities[k];
    return Vec3{d[k].x + u.x * s_in, d[k].y + u.y * s_in, d[k].z + u.z * s_in};
  };

  std::int64_t reversed = 0, surfaces = 0;
  for (std::size_t r = 0; r < t.size(); ++r) {
    const auto& b = ref.bubbles[t.id[r]];
    // The reference keeps 1 / (1 / a) across the flow: equal to rounding.
    EXPECT_EQ(t.semi_axes[r].x, b.semi_axes.x);
    EXPECT_NEAR(t.semi_axes[r].y, b.semi_axes.y, 1e-15 * b.semi_axes.y);
    EXPECT_NEAR(t.semi_axes[r].z, b.semi_axes.z, 1e-15 * b.semi_axes.z);
    // The volume-equivalent diameter: a_x a_y a_z = (d / 2)^3.
    EXPECT_NEAR(std::cbrt(b.semi_axes.x * b.semi_axes.y * b.semi_axes.z), 0.5 * t.diameter[r], 1e-15);
    reversed += t.extra_passes[r] > 0;
    // Velocity: the mean over the interaction interval.
    const double span = t.interaction_end[r] - t.interaction_start[r];
    if (span > 0.0) {
      const Vec3 a = displacement(t.interaction_start[r]), e = displacement(t.interaction_end[r]);
      EXPECT_NEAR(t.velocity[r].x, (e.x - a.x) / span, 1e-9 * s.velocity) << "bubble " << t.id[r];
      EXPECT_NEAR(t.velocity[r].y, (e.y - a.y) / span, 1e-9 * s.velocity) << "bubble " << t.id[r];
      EXPECT_NEAR(t.velocity[r].z, (e.z - a.z) / span, 1e-9 * s.velocity) << "bubble " << t.id[r];
    }
    for (std::size_t k = 0; k < t.tip_count; ++k) {
      const TipPierce& p = t.pierce(r, k);
      if (!p.pierced()) continue;
      // At each interface the tip is on the surface, |(p - c) / a| = 1, and
      // the normal is along (p - c) / a^2.
      auto check = [&](double time, const std::array<float, 3>& normal) {
        const Vec3 dt = displacement(time);
        const Vec3& tip = ref.tips[k];
        const Vec3 rel{tip.x - (b.entry.x + dt.x - b.key.x),
                       tip.y - periodic(b.entry.y + dt.y - b.key.y, ref.control_volume.y),
                       tip.z - periodic(b.entry.z + dt.z - b.key.z, ref.control_volume.z)};
        const Vec3 q{rel.x / b.semi_axes.x, rel.y / b.semi_axes.y, rel.z / b.semi_axes.z};
        EXPECT_NEAR(q.x * q.x + q.y * q.y + q.z * q.z, 1.0, 1e-8) << "bubble " << t.id[r] << " tip " << k;
        const Vec3 g{q.x / b.semi_axes.x, q.y / b.semi_axes.y, q.z / b.semi_axes.z};
        const double n = std::sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
        EXPECT_NEAR(normal[0], g.x / n, 1e-5) << "bubble " << t.id[r] << " tip " << k;
        EXPECT_NEAR(normal[1], g.y / n, 1e-5) << "bubble " << t.id[r] << " tip " << k;
        EXPECT_NEAR(normal[2], g.z / n, 1e-5) << "bubble " << t.id[r] << " tip " << k;
        ++surfaces;
        return rel;
      };
      const Vec3 front = check(p.front, p.front_normal);
      if (p.censored()) continue;
      const Vec3 rear = check(p.rear, p.rear_normal);
      EXPECT_NEAR(p.chord, std::hypot(rear.x - front.x, rear.y - front.y, rear.z - front.z), 1e-9)
          << "bubble " << t.id[r] << " tip " << k;
    }
  }
  EXPECT_GT(reversed, 0) << "the scene must bring bubbles back over a tip";
  EXPECT_GT(surfaces, 1000);
  expect_counts_match(out);
}

TEST(BubbleTruth, TurbulentRecordingAgreesWithTheTableWithinHalfASample) {
  Scene s = turbulent_scene();
  s.tu = 0.25;  // no reversal: the table's passes are all the recording holds
  s.void_fraction = 0.25;
  const Synthesis out = run_truth(s);
  ASSERT_TRUE(out.bubbles);
  expect_counts_match(out);
  expect_recording_matches_table(out, s);
}

// Same seed, same table: whatever the chunk of velocity steps, and whether
// two syntheses run one after the other or at once on two threads (the
// synthesiser runs on one thread and shares no state between runs).
void expect_same(const BubbleTruth& a, const BubbleTruth& b) {
  static_assert(sizeof(TipPierce) == 48 && sizeof(Vec3) == 24, "compared bytewise: no padding");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.tip_count, b.tip_count);
  auto bytes = [](const auto& x, const auto& y) {
    return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0;
  };
  EXPECT_TRUE(bytes(a.id, b.id));
  EXPECT_TRUE(bytes(a.diameter, b.diameter));
  EXPECT_TRUE(bytes(a.semi_axes, b.semi_axes));
  EXPECT_TRUE(bytes(a.velocity, b.velocity));
  EXPECT_TRUE(bytes(a.interaction_start, b.interaction_start));
  EXPECT_TRUE(bytes(a.interaction_end, b.interaction_end));
  EXPECT_TRUE(bytes(a.extra_passes, b.extra_passes));
  EXPECT_TRUE(bytes(a.pierces, b.pierces));
}

TEST(BubbleTruth, SameSeedSameTableWhateverTheChunksAndThreads) {
  const Scene s = turbulent_scene();
  const Synthesis one = run_truth(s);
  const Synthesis chunked = run_truth(s, true, false, 977);
  ASSERT_TRUE(one.bubbles && chunked.bubbles);
  ASSERT_GT(one.bubbles->size(), 100u);
  expect_same(*one.bubbles, *chunked.bubbles);
  Synthesis a, b;
  std::thread first([&] { a = run_truth(s, true, false, 977); });
  std::thread second([&] { b = run_truth(s); });
  first.join();
  second.join();
  expect_same(*one.bubbles, *a.bubbles);
  expect_same(*one.bubbles, *b.bubbles);
  for (std::size_t k = 0; k < one.truth.tips.size(); ++k) {
    EXPECT_EQ(one.truth.tips[k].interfacial_area, a.truth.tips[k].interfacial_area);
    EXPECT_EQ(one.truth.tips[k].interfacial_area, chunked.truth.tips[k].interfacial_area);
  }
}

TEST(BubbleTruth, OffByDefaultAndChangesNothingElse) {
  const Scene s = turbulent_scene();
  EXPECT_FALSE(SynthesisOptions{}.bubble_truth);
  const Synthesis off = run_truth(s, false);
  const Synthesis on = run_truth(s, true);
  EXPECT_FALSE(off.bubbles);
  ASSERT_TRUE(on.bubbles);
  ASSERT_EQ(off.signals.size(), on.signals.size());
  for (std::size_t k = 0; k < off.signals.size(); ++k) {
    EXPECT_FALSE(off.truth.tips[k].interfacial_area);
    EXPECT_TRUE(on.truth.tips[k].interfacial_area);
    EXPECT_TRUE(off.signals[k].intervals == on.signals[k].intervals) << "tip " << k;
    EXPECT_EQ(off.truth.tips[k].bubbles_pierced, on.truth.tips[k].bubbles_pierced);
  }
  EXPECT_EQ(off.truth.realised.mean_velocity, on.truth.realised.mean_velocity);
}

// The interfacial area concentration for one sphere size, Tu = 0, arrivals
// equally spaced along the flow (the tip sees c exactly in expectation).
//
// Exact part. On a straight path at speed U through a sphere of radius R at
// an offset with h = chord / 2, each interface has |u . n| = U h / R, so the
// truth is (1/T) sum over interfaces in the record of R / (U h) = d / (U chord):
// recomputed from the table's chords (found from displacements, not from
// the normals the truth uses).
//
// Statistical part: against 6 c / d_b. With N pierces a tip's truth is
// (2 / (U T)) sum_k X_k, X_k = R / h_k = 1 / cos(theta_k), the offset b_k
// uniform on the disc: P(X > x) = x^-2 for x >= 1, E[X] = 2, so the
// expectation is 4 E[N] / (U T) = 4 (1.5 c U / d) / U = 6 c / d. Relative
// error: eps = (N / E[N]) (mean X / 2) - 1, about dN + dX.
//  - dN: entries are equally spaced, each pierces with p = pi R^2 / A
//    independently (uniform lateral entry): Var(N) <= E[N], sd(dN) <= 1/sqrt(N).
//  - dX: X has an infinite variance (the grazing pierces), so truncate at
//    m = 10 sqrt(N): P(any X > m) <= N / m^2 = 1 %; below m,
//    E[X^2] = integral_1^m x^2 2 x^-3 dx = 2 ln m, so sd(dX) <= sqrt(2 ln m / N) / 2;
//    the truncation moves the mean by E[X; X > m] / 2 = 1 / m.
// The bound is 4 (sd(dN) + sd(dX)) + 1 / m: with N ~ 60,000 about 5 %.
TEST(BubbleTruth, InterfacialAreaOfOneSphereSizeIsSixCOverD) {
  Scene s = straight_scene();  // Tu = 0, d_b = 4 mm, four tips
  s.velocity = 5.0;
  s.arrival = synth::ArrivalRule::equal_space;
  s.void_fraction = 0.1;
  s.fs = 20e3;
  s.realisation_step = 1e-3;  // the path is exact at any step without turbulence
  const double rate = 1.5 * s.void_fraction * s.velocity / s.bubble_diameter;
  s.duration = std::ceil(60'000.0 / rate);
  const Synthesis out = run_truth(s);
  ASSERT_TRUE(out.bubbles);
  const BubbleTruth& t = *out.bubbles;
  const double expected = 6.0 * s.void_fraction / s.bubble_diameter;
  EXPECT_NEAR(out.truth.expected_interfacial_area, expected, 1e-12 * expected);
  for (std::size_t k = 0; k < t.tip_count; ++k) {
    ASSERT_TRUE(out.truth.tips[k].interfacial_area);
    const double area = *out.truth.tips[k].interfacial_area;
    double from_chords = 0.0;
    std::int64_t n = 0;
    for (std::size_t r = 0; r < t.size(); ++r) {
      const TipPierce& p = t.pierce(r, k);
      if (!p.pierced()) continue;
      ++n;
      ASSERT_FALSE(p.censored()) << "a pierce at the record's end: its chord is unknown";
      const double per_interface = s.bubble_diameter / (s.velocity * p.chord);
      from_chords += (p.front >= 0.0 ? per_interface : 0.0) + per_interface;
    }
    from_chords /= s.duration;
    EXPECT_NEAR(area / from_chords, 1.0, 1e-5) << "tip " << k;

    const double N = static_cast<double>(n);
    const double m = 10.0 * std::sqrt(N);
    const double tolerance = 4.0 * (1.0 / std::sqrt(N) + std::sqrt(2.0 * std::log(m) / N) / 2.0) + 1.0 / m;
    ASSERT_LT(tolerance, 0.055);
    EXPECT_NEAR(area / expected, 1.0, tolerance) << "tip " << k << ", " << n << " bubbles";
  }
}

// The imposed expectation c E[S] / E[V] for spheroids of the sphere's
// volume, against Knud Thomsen's approximation of an ellipsoid's surface,
// 4 pi ((a^p b^p + a^p c^p + b^p c^p) / 3)^(1/p), p = 1.6075, whose
// relative error is below 1.061 %: independent of the exact formulas.
TEST(BubbleTruth, ExpectedAreaOfSpheroidsAgainstThomsensApproximation) {
  Scene s = straight_scene();
  s.duration = 0.01;
  const double sphere = run_truth(s, false).truth.expected_interfacial_area;
  EXPECT_NEAR(sphere, 6.0 * s.void_fraction / s.bubble_diameter, 1e-12 * sphere);
  for (const double aspect : {0.4, 0.7, 1.5, 3.0}) {
    s.aspect_ratio = aspect;
    // Semi-axes for d = 2: a_x = aspect^(2/3), lateral aspect^(-1/3).
    const double a = std::cbrt(aspect * aspect), b = 1.0 / std::cbrt(aspect), p = 1.6075;
    const double ab = std::pow(a * b, p), bb = std::pow(b * b, p);
    const double ratio = std::pow((2.0 * ab + bb) / 3.0, 1.0 / p);  // over the unit sphere's 4 pi
    EXPECT_NEAR(run_truth(s, false).truth.expected_interfacial_area / sphere / ratio, 1.0, 0.0107) << "aspect " << aspect;
    EXPECT_GT(ratio, 1.0) << "a spheroid has more surface than the sphere of its volume";
  }
}

TEST(BubbleTruth, CsvRoundTripsExactlyAndRefusesWhatItDoesNotWrite) {
  const Synthesis out = run_truth(turbulent_scene());
  ASSERT_TRUE(out.bubbles);
  const auto path = pdp_test::test_file("bubbles.csv");
  synth::write_bubble_truth_csv(path, *out.bubbles);
  const BubbleTruth back = synth::read_bubble_truth_csv(path);
  expect_same(*out.bubbles, back);
  EXPECT_EQ(synth::bubble_truth_path("dir/rec.flac"), std::filesystem::path("dir/rec.truth.bubbles.csv"));

  // A cell that is no number names the file, the line and the column.
  std::ifstream in(path);
  std::string header, first;
  std::getline(in, header);
  std::getline(in, first);
  const auto cells = awcc::split_cells(first);
  const auto columns = synth::bubble_truth_columns(out.bubbles->tip_count);
  ASSERT_EQ(cells.size(), columns.size());
  const auto column = static_cast<std::size_t>(std::find(columns.begin(), columns.end(), "tip1_rear") - columns.begin());
  std::string bad = header + "\n";
  for (std::size_t i = 0; i < cells.size(); ++i) bad += (i ? "," : "") + (i == column ? std::string("soon") : cells[i]);
  const auto bad_path = pdp_test::test_file("bad.csv");
  std::ofstream(bad_path) << bad << "\n";
  try {
    synth::read_bubble_truth_csv(bad_path);
    ADD_FAILURE() << "a bad cell was read";
  } catch (const awcc::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.csv: line 2: column tip1_rear: 'soon' is not a finite number"), std::string::npos) << what;
  }
}

}  // namespace
