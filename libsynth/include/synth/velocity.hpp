#pragma once
// Fluid velocity at one point: a 3-D Ornstein-Uhlenbeck (Langevin) process
// (METHOD.md 5.1).
//
// Component i has mean m_i (m_x = velocity, m_y = m_z = 0), standard deviation
// sigma_i = velocity * Tu_i and integral time scale T_i. With a_i = exp(-dt/T_i)
// the exact update over a step dt is
//
//   u_i(t + dt) = m_i + a_i (u_i(t) - m_i) + sigma_i sqrt(1 - a_i^2) eta_i,
//
// exact in distribution for every dt/T_i. The forcing eta is Gaussian with unit
// variances and correlation
//
//   rho_eta,ij = rho_ij (1 - a_i a_j) / sqrt((1 - a_i^2)(1 - a_j^2)),
//
// which makes the stationary correlation of u_i and u_j equal rho_ij (the
// stationary covariance C solves C = A C A + Q, so Q_ij = C_ij (1 - a_i a_j)).
// 1 - a^2 and 1 - a_i a_j are computed with expm1 so that dt/T -> 0 stays
// accurate. The process starts from its stationary distribution
// u(0) = m + sigma L xi, L L^T = rho.
//
// The Euler step u + (m - u) dt/T + sigma sqrt(2 dt/T) eta (forcing correlation
// rho) is kept for comparison: its stationary variance is sigma^2 / (1 - dt/2T),
// biased unless dt << T, and it diverges for dt/T > 2 (Scene::validate refuses it).

#include <array>
#include <span>
#include <vector>

#include "synth/random.hpp"
#include "synth/scene.hpp"

namespace synth {

class VelocityProcess {
 public:
  /// Throws std::invalid_argument if the forcing correlation is not positive
  /// definite at this step (possible only for very different T_i).
  VelocityProcess(const Scene& scene, double dt);

  /// The current velocity, then advances one step. Consumes the velocity
  /// stream in step order only, so any chunking gives the same series.
  Vec3 next();

  /// Fills `out` with consecutive velocities (same as calling next() repeatedly:
  /// the forcing is drawn in one block, in the same order).
  void generate(std::span<Vec3> out);

  [[nodiscard]] double step() const { return dt_; }

 private:
  // Writes the current velocity to `current` and steps with the forcing draws xi[0..2].
  void advance(Vec3& current, const double* xi) {
    current = {state_[0], state_[1], state_[2]};
    const double e0 = forcing_[0] * xi[0];
    const double e1 = forcing_[3] * xi[0] + forcing_[4] * xi[1];
    const double e2 = forcing_[6] * xi[0] + forcing_[7] * xi[1] + forcing_[8] * xi[2];
    state_[0] = mean_[0] + decay_[0] * (state_[0] - mean_[0]) + innovation_[0] * e0;
    state_[1] = mean_[1] + decay_[1] * (state_[1] - mean_[1]) + innovation_[1] * e1;
    state_[2] = mean_[2] + decay_[2] * (state_[2] - mean_[2]) + innovation_[2] * e2;
  }

  Rng rng_;
  double dt_;
  std::array<double, 3> mean_{};
  std::array<double, 3> sigma_{};
  std::array<double, 3> decay_{};     // a_i (exact) or 1 - dt/T_i (Euler)
  std::array<double, 3> innovation_{};  // sigma_i sqrt(1 - a_i^2) or sigma_i sqrt(2 dt / T_i)
  std::array<double, 9> forcing_{};   // lower Cholesky factor of the forcing correlation
  std::array<double, 3> state_{};     // current velocity
  std::vector<double> forcing_draws_;  // scratch of generate(): 3 normals a step
};

/// Lower Cholesky factor (row-major 3x3) of the forcing correlation for the
/// exact update at step dt; throws std::invalid_argument when not positive definite.
std::array<double, 9> forcing_cholesky(const Scene& scene, double dt);

}  // namespace synth
