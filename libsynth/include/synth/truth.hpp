#pragma once
// What the synthetic probe knows and a real probe never does: the imposed
// scene, the statistics actually realised by the random velocity series and
// bubbles, and the window-averaged true velocity over any interval.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "synth/scene.hpp"

namespace synth {

/// Statistics of the generated velocity series over the record [0, duration).
/// Time averages of the piecewise-constant velocity the bubbles follow.
struct RealisedFlow {
  std::array<double, 3> mean_velocity{};          ///< m/s (x, y, z)
  std::array<double, 3> rms_velocity{};           ///< standard deviation, m/s
  std::array<double, 3> turbulence_intensity{};   ///< rms / |mean velocity vector|, -
  /// Integral of the autocorrelation from lag 0 to its first zero (trapezoid
  /// rule on a series decimated to ~20 points per imposed T), s. Empty for a
  /// component without fluctuation.
  std::array<std::optional<double>, 3> integral_time_scale{};
  std::optional<double> rho_xy, rho_xz, rho_yz;   ///< correlation coefficients, -
  std::int64_t steps = 0;                         ///< velocity steps in the record
};

struct TipTruth {
  Vec3 position;                      ///< m, as given in the scene
  double void_fraction = 0.0;         ///< air samples / samples, - (either dispersed phase)
  /// Distinct dispersed particles whose piercing overlaps the record:
  /// bubbles, or droplets in the spray region (Truth::dispersed_phase).
  std::int64_t bubbles_pierced = 0;
  std::int64_t chords = 0;            ///< air intervals in the sampled signal (either phase)
  /// The true local interfacial area concentration at the tip, 1/m, with
  /// SynthesisOptions::bubble_truth (else empty): the time average of the
  /// interfaces passing the point,
  ///
  ///   a = (1/T) sum over interfaces i crossing the tip in [0, T) of 1 / |u_i . n_i|,
  ///
  /// u_i the bubble's velocity at the instant of crossing, n_i the surface's
  /// unit normal there (Ishii 1975; Kataoka et al. 1986). It is the
  /// definition of the local time-averaged IAC, so it is what a probe's
  /// estimator (Shen & Nakamura 2014 Eq. 54 sums the same terms from
  /// estimated velocities and normals) converges to, and it holds whatever
  /// the shapes, sizes and velocity fluctuations. Taken over the control
  /// volume instead (bubble surface per volume), it would miss what the
  /// point sees: the tip's void fraction is c (1 + Tu_x^2) under equal-time
  /// arrivals, and the IAC at the point scales with it. For one sphere size
  /// its expectation is 6 c_tip / d_b: a pierce at a uniform offset on the
  /// disc gives E[1 / cos theta] = 2 per interface. Droplets have the same
  /// interfaces: there c_tip is the tip's droplet fraction 1 - c_tip,air,
  /// (1 - c)(1 + Tu_x^2) under equal-time arrivals.
  std::optional<double> interfacial_area;
};

struct PairTruth {
  int first = 0, second = 0;               ///< tip indices
  std::int64_t pierced_by_both = 0;        ///< distinct particles (bubbles or droplets) pierced by both tips in the record
};

struct Truth {
  Scene imposed;
  double realisation_step = 0.0;           ///< dt_r actually used, s
  double control_volume[3] = {0, 0, 0};    ///< edges L_x, L_y, L_z, m
  /// What the tips pierce: bubbles (c <= 0.5), or droplets at 1 - c
  /// (synth::dispersed_phase). The counts and rates below are of these
  /// particles, whichever they are, with c_d = c or 1 - c.
  DispersedPhase dispersed_phase = DispersedPhase::bubbles;
  double bubble_rate = 0.0;                ///< particles entering the control volume per second, 1/s
  /// Mean pierce rate of a tip, c_d u E[pi a_y a_z] / E[V] (1.5 c_d u / d_b
  /// for spheres), 1/s.
  double expected_pierce_rate = 0.0;
  /// c_d E[S_b] / E[V_b] of the imposed population (S_b the surface of the
  /// particle's ellipsoid): 6 c_d / d_b for one sphere size, 1/m. The realised
  /// value at each tip is TipTruth::interfacial_area.
  double expected_interfacial_area = 0.0;
  RealisedFlow realised;
  std::vector<TipTruth> tips;
  std::vector<PairTruth> pairs;
  std::int64_t bubbles_generated = 0;      ///< particles entering during [0, duration)
  std::int64_t overlaps_unresolved = 0;    ///< particles placed overlapping after all retries
  /// Under the space arrival rules, the dispersed volume that the record's
  /// particles placed overlapping share with those they overlap, per volume
  /// of flow through the control volume's cross-section in the record (A
  /// times the streamwise displacement), -: the arrivals were brought forward
  /// by as much, so the realised dispersed fraction is the imposed one
  /// (synth/synthesiser.hpp, "Dense placement"). 0 when no particle overlaps,
  /// and under the time rules, which compensate nothing: there overlaps come
  /// from particles piling up while the flow is slow, and the realised
  /// fraction falls short by their shared volume.
  double compensated_volume_fraction = 0.0;
  std::int64_t reentries_missed = 0;       ///< steps where a retired bubble could have come back (0 expected)
  std::int64_t sample_count = 0;

  /// A readable multi-line summary.
  [[nodiscard]] std::string report() const;
};

/// Window-averaged true streamwise velocity <u_x>_W = (1/(t1 - t0)) integral
/// of u_x over [t0, t1), answered in O(1) from the cumulative displacement
/// at each velocity step.
class VelocityHistory {
 public:
  VelocityHistory() = default;
  /// An empty history with X_0 = 0 at t = 0, to be extended step by step.
  explicit VelocityHistory(double step) : step_(step) { push_back(0.0); }
  VelocityHistory(double step, const std::vector<double>& cumulative_displacement) : step_(step) {
    for (const double x : cumulative_displacement) push_back(x);
  }
  VelocityHistory(VelocityHistory&& other) noexcept { *this = std::move(other); }
  VelocityHistory& operator=(VelocityHistory&& other) noexcept {
    step_ = other.step_;
    size_ = std::exchange(other.size_, 0);
    blocks_ = std::move(other.blocks_);
    other.blocks_.clear();
    next_ = std::exchange(other.next_, nullptr);
    end_ = std::exchange(other.end_, nullptr);
    return *this;
  }

  /// Appends X at the next velocity step. Once a step of the synthesis:
  /// inline, a store and a compare (a vector's push_back, out of line, was
  /// 3 % of a 300 s run).
  void push_back(double x) {
    if (next_ == end_) add_block();
    *next_++ = x;
    ++size_;
  }
  /// X at the last step kept, m.
  [[nodiscard]] double back() const { return next_[-1]; }

  /// Mean of u_x over [t0, t1), m/s; t0 < t1 within the record. For t0 == t1
  /// the velocity at t0.
  [[nodiscard]] double mean_velocity(double t0, double t1) const;
  /// Streamwise displacement since t = 0, m.
  [[nodiscard]] double displacement(double t) const;
  [[nodiscard]] double step() const { return step_; }
  [[nodiscard]] double end_time() const { return step_ * static_cast<double>(size_ - 1); }

 private:
  // Blocks of 2^20 steps (8 MB), not one array: a 300 s record holds 6
  // million steps, 47 MB, above the largest block glibc keeps in the heap
  // (32 MB), so one array went to mmap and was faulted in again by every
  // run of a sweep; blocks are reused (awcc::keep_freed_memory). Left
  // uninitialised (every step read is written first): zeroing them was
  // a pass over 47 MB.
  static constexpr std::size_t block_shift = 20;
  static constexpr std::size_t block_size = std::size_t{1} << block_shift;
  static constexpr std::size_t block_mask = block_size - 1;
  [[nodiscard]] double at(std::size_t k) const { return blocks_[k >> block_shift][k & block_mask]; }
  void add_block() {
    blocks_.push_back(std::make_unique_for_overwrite<double[]>(block_size));
    next_ = blocks_.back().get();
    end_ = next_ + block_size;
  }

  double step_ = 0.0;
  std::size_t size_ = 0;  // steps kept: X_k at t = k step, X_0 = 0
  std::vector<std::unique_ptr<double[]>> blocks_;  // X_k in blocks_[k >> block_shift][k & block_mask]
  double* next_ = nullptr;  // where the next step goes, in the last block
  double* end_ = nullptr;   // the last block's end
};

}  // namespace synth
