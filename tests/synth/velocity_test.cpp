#include "synth/velocity.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

using synth::Scene;
using synth::Vec3;
using synth::VelocityProcess;

// Sampling theory for a stationary AR(1) series x_n with coefficient
// a = exp(-dt/T), variance s^2 and N samples (N >> 1/(1 - a)):
//   Var(mean)      = s^2 / N * (1 + a) / (1 - a)
//   Var(variance)  = 2 s^4 / N * (1 + a^2) / (1 - a^2)
//   Var(r_1)       = (1 - a^2) / N                     (lag-1 autocorrelation, Bartlett)
//   Var(rho_xz)    = (1 - rho^2)^2 / N * (1 + a^2) / (1 - a^2)   (two AR(1), same a)
// The exact update makes each component exactly such a series with
// s = velocity * Tu and the requested rho, for every dt/T. Each test allows
// 5 standard errors: a false alarm has probability below 1e-6 per check.
struct Moments {
  double mean[3] = {0, 0, 0};
  double var[3] = {0, 0, 0};
  double rho_xz = 0;
  double r1[3] = {0, 0, 0};
};

Moments measure(const Scene& scene, double dt, std::size_t n) {
  VelocityProcess p(scene, dt);
  std::vector<Vec3> v(n);
  p.generate(v);
  Moments m;
  auto comp = [](const Vec3& u, int i) { return i == 0 ? u.x : (i == 1 ? u.y : u.z); };
  for (int i = 0; i < 3; ++i) {
    long double s = 0;
    for (const auto& u : v) s += comp(u, i);
    m.mean[i] = static_cast<double>(s / n);
    long double ss = 0, lag = 0;
    for (std::size_t k = 0; k < n; ++k) {
      const long double d = comp(v[k], i) - m.mean[i];
      ss += d * d;
      if (k + 1 < n) lag += d * (comp(v[k + 1], i) - m.mean[i]);
    }
    m.var[i] = static_cast<double>(ss / n);
    m.r1[i] = static_cast<double>(lag / ss);
  }
  long double sxz = 0;
  for (const auto& u : v) sxz += (u.x - m.mean[0]) * (u.z - m.mean[2]);
  m.rho_xz = static_cast<double>(sxz / n) / std::sqrt(m.var[0] * m.var[2]);
  return m;
}

class ExactUpdate : public ::testing::TestWithParam<double> {};

TEST_P(ExactUpdate, StationaryStatisticsMatchTheImposedOnes) {
  const double h = GetParam();  // dt / T
  Scene s;
  s.time_scale = 0.1;
  const double dt = h * s.time_scale;
  const std::size_t n = 1'000'000;
  const Moments m = measure(s, dt, n);
  const double a = std::exp(-h);
  const double sig[3] = {s.velocity * s.tu, s.velocity * s.tu_y, s.velocity * s.tu_z};
  const double mean[3] = {s.velocity, 0.0, 0.0};
  for (int i = 0; i < 3; ++i) {
    const double se_mean = sig[i] * std::sqrt((1 + a) / (1 - a) / n);
    EXPECT_NEAR(m.mean[i], mean[i], 5 * se_mean) << "component " << i << " dt/T " << h;
    const double se_var = sig[i] * sig[i] * std::sqrt(2.0 * (1 + a * a) / (1 - a * a) / n);
    EXPECT_NEAR(m.var[i], sig[i] * sig[i], 5 * se_var) << "component " << i << " dt/T " << h;
    // Integral time scale through the lag-1 autocorrelation: r_1 = exp(-dt/T).
    EXPECT_NEAR(m.r1[i], a, 5 * std::sqrt((1 - a * a) / n)) << "component " << i << " dt/T " << h;
  }
  const double rho = s.rho_xz;
  const double se_rho = (1 - rho * rho) * std::sqrt((1 + a * a) / (1 - a * a) / n);
  EXPECT_NEAR(m.rho_xz, rho, 5 * se_rho) << "dt/T " << h;
  if (h <= 1.0) {
    // Where the series resolves T, the time scale itself: T = -dt / ln r_1,
    // with standard error (delta method) T * se(r_1) / (a h).
    const double t_est = -dt / std::log(m.r1[0]);
    const double se_t = s.time_scale * std::sqrt((1 - a * a) / n) / (a * h);
    EXPECT_NEAR(t_est, s.time_scale, 5 * se_t) << "dt/T " << h;
  }
}

INSTANTIATE_TEST_SUITE_P(DtOverT, ExactUpdate, ::testing::Values(0.001, 0.01, 1.0, 10.0, 100.0, 1000.0));

TEST(EulerUpdate, IsBiasedAsPredictedWhileExactIsNot) {
  // Euler at dt/T = 1 is the AR(1) x' = 0 * x + sigma sqrt(2) eta: variance
  // 2 sigma^2 = sigma^2 / (1 - h/2), twice the imposed one.
  Scene s;
  s.velocity_update = synth::VelocityUpdate::euler;
  const double h = 1.0;
  const std::size_t n = 400'000;
  const Moments m = measure(s, h * s.time_scale, n);
  const double sig2 = std::pow(s.velocity * s.tu, 2);
  const double b = 1.0 - h;  // Euler AR coefficient
  const double expected = sig2 / (1.0 - h / 2.0);
  const double se = expected * std::sqrt(2.0 * (1 + b * b) / (1 - b * b) / n);
  EXPECT_NEAR(m.var[0], expected, 5 * se);
  EXPECT_GT(m.var[0], 1.5 * sig2);
}

TEST(VelocityProcess, ChunkedGenerationGivesTheSameSeries) {
  Scene s;
  VelocityProcess whole(s, 1e-4), pieces(s, 1e-4);
  std::vector<Vec3> a(10007), b(10007);
  whole.generate(a);
  std::size_t pos = 0;
  for (std::size_t chunk : {1u, 2u, 999u, 4096u, 5000u}) {
    const std::size_t n = std::min(chunk, b.size() - pos);
    pieces.generate(std::span<Vec3>(b.data() + pos, n));
    pos += n;
  }
  ASSERT_EQ(pos, b.size());
  EXPECT_EQ(a, b);
}

TEST(VelocityProcess, SeedsGiveDifferentSeries) {
  Scene s1, s2;
  s2.seed = 2;
  VelocityProcess p1(s1, 1e-3), p2(s2, 1e-3);
  EXPECT_NE(p1.next(), p2.next());
}

TEST(ForcingCorrelation, RefusedWhenTimeScalesMakeItImpossible) {
  // Strong correlation between components with time scales 1000x apart: the
  // required forcing correlation exceeds 1 for small steps.
  Scene s;
  s.rho_xz = -0.9;
  s.time_scale = 1.0;
  s.time_scale_z = 1e-3;
  EXPECT_THROW(synth::forcing_cholesky(s, 1e-5), std::invalid_argument);
  // Equal time scales: the forcing correlation is rho itself.
  Scene e;
  const auto l = synth::forcing_cholesky(e, 1e-3);
  // L(2,0) = rho_xz for a unit-diagonal matrix with rho_xy = 0.
  EXPECT_NEAR(l[6], e.rho_xz, 1e-12);
}

TEST(ZeroTurbulence, VelocityIsExactlyTheMean) {
  Scene s;
  s.tu = s.tu_y = s.tu_z = 0.0;
  VelocityProcess p(s, 1e-4);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 u = p.next();
    ASSERT_EQ(u, (Vec3{10.0, 0.0, 0.0}));
  }
}

}  // namespace
