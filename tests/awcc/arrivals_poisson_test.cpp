// The random-arrival reference of awcc/arrivals.hpp against a Poisson
// process: libsynth's Poisson arrivals of small bubbles in a steady flow.
#include <gtest/gtest.h>

#include <cmath>

#include "awcc/arrivals.hpp"
#include "synth/synthesiser.hpp"

namespace {

TEST(Arrivals, ObservedIntervalsOfAPoissonProcessAgreeWithTheReference) {
  // Bubbles of 0.2 mm at 4 m/s without turbulence, entering as a Poisson
  // process in time; c = 0.0005: about 15 pierced bubbles per second, 6000 s.
  synth::Scene s;
  s.velocity = 4.0;
  s.tu = s.tu_y = s.tu_z = 0.0;
  s.rho_xz = 0.0;
  s.void_fraction = 0.0005;
  s.bubble_diameter = 0.2e-3;
  s.arrival = synth::ArrivalRule::poisson_time;
  s.fs = 200e3;
  s.duration = 6000.0;
  s.seed = 17;
  const auto out = synth::synthesise(s);
  const auto chords = awcc::complete_chords(out.signals[0]);
  awcc::ArrivalOptions o;
  o.bin_width = 5e-3;
  o.bins = 40;
  o.time_classes.clear();  // one class: every bubble
  const auto a = awcc::arrival_analysis(chords, out.signals[0].void_fraction(), awcc::ChordBasis::time, o);
  ASSERT_EQ(a.status, awcc::ClusterStatus::ok);
  ASSERT_EQ(a.classes.size(), 1u);
  const auto& c = a.classes[0];
  const double n = static_cast<double>(c.intervals);
  ASSERT_GT(n, 50'000.0);
  // The bound. The pierced bubbles of a Poisson entry process are a thinned
  // Poisson process, so its intervals are independent exponentials and the
  // bin counts multinomial: O_m - n p_m has sd sqrt(n p_m (1 - p_m)); 5 sd
  // for each of the 41 bins is exceeded with probability below 41 x 5.7e-7.
  // Two departures from the model are added: the reference's finite record
  // ((T - t) / T and 1 / N, below 1e-3 of p_m here), and bubbles too close
  // to be seen apart: the synthesiser moves overlapping bubbles and the
  // probe merges touching ones, which changes at most two intervals per
  // pair closer than tau = 2 d / u (0.1 ms), i.e. at most 2 n lambda tau
  // counts in any bin (lambda = intervals per second).
  const double lambda = n / s.duration, tau = 2.0 * s.bubble_diameter / s.velocity;
  double total = 0.0;
  for (std::size_t m = 0; m < c.counts.size(); ++m) {
    const double p = c.reference[m], expected = n * p;
    const double bound = 5.0 * std::sqrt(expected * (1.0 - p)) + 1e-3 * expected + 2.0 * n * lambda * tau;
    EXPECT_LE(std::fabs(static_cast<double>(c.counts[m]) - expected), bound) << "bin " << m;
    total += p;
  }
  EXPECT_NEAR(total, 1.0, 1e-9);
  // No grouping: the excess of short intervals is 1 within its error (and the dead time).
  EXPECT_LE(std::fabs(*c.excess_first_bin - 1.0), 5.0 * *c.excess_first_bin_se + 2.0 * n * lambda * tau / (n * c.reference[0]));
}

}  // namespace
