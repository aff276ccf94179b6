#include "synth/velocity.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

namespace synth {
namespace {

std::array<double, 9> cholesky(const Eigen::Matrix3d& m, std::string_view what) {
  Eigen::LLT<Eigen::Matrix3d> llt(m);
  if (llt.info() != Eigen::Success) {
    throw std::invalid_argument(fmt::format("the {} correlation matrix is not positive definite", what));
  }
  const Eigen::Matrix3d l = llt.matrixL();
  std::array<double, 9> out{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(3 * r + c)] = l(r, c);
  return out;
}

Eigen::Matrix3d rho_matrix(const Scene& s) {
  Eigen::Matrix3d r;
  r << 1.0, s.rho_xy, s.rho_xz, s.rho_xy, 1.0, s.rho_yz, s.rho_xz, s.rho_yz, 1.0;
  return r;
}

}  // namespace

std::array<double, 9> forcing_cholesky(const Scene& scene, double dt) {
  const Eigen::Matrix3d rho = rho_matrix(scene);
  Eigen::Matrix3d eta = Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (i == j) continue;
      const double hi = dt / scene.time_scale_of(i);
      const double hj = dt / scene.time_scale_of(j);
      const double one_minus_aiaj = -std::expm1(-(hi + hj));
      const double one_minus_ai2 = -std::expm1(-2.0 * hi);
      const double one_minus_aj2 = -std::expm1(-2.0 * hj);
      eta(i, j) = rho(i, j) * one_minus_aiaj / std::sqrt(one_minus_ai2 * one_minus_aj2);
    }
  }
  try {
    return cholesky(eta, "forcing");
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument(fmt::format(
        "the velocity forcing correlation at realisation-step {} is not positive definite: the requested "
        "rho-xy/rho-xz/rho-yz cannot be reached with time scales this different; reduce the correlations "
        "or make the time scales closer",
        awcc::format_quantity(dt, awcc::Dimension::time)));
  }
}

VelocityProcess::VelocityProcess(const Scene& scene, double dt)
    : rng_(scene.seed, Stream::velocity), dt_(dt) {
  mean_ = {scene.velocity, 0.0, 0.0};
  for (int i = 0; i < 3; ++i) {
    const auto k = static_cast<std::size_t>(i);
    sigma_[k] = scene.velocity * scene.tu_of(i);
    const double h = dt / scene.time_scale_of(i);
    if (scene.velocity_update == VelocityUpdate::exact) {
      decay_[k] = std::exp(-h);
      innovation_[k] = sigma_[k] * std::sqrt(-std::expm1(-2.0 * h));
    } else {
      decay_[k] = 1.0 - h;
      innovation_[k] = sigma_[k] * std::sqrt(2.0 * h);
    }
  }
  forcing_ = scene.velocity_update == VelocityUpdate::exact ? forcing_cholesky(scene, dt)
                                                           : cholesky(rho_matrix(scene), "velocity");
  // Stationary start: u(0) = m + sigma L xi with L L^T = rho.
  const auto stationary = cholesky(rho_matrix(scene), "velocity");
  const double xi[3] = {rng_.normal(), rng_.normal(), rng_.normal()};
  for (std::size_t i = 0; i < 3; ++i) {
    double e = 0.0;
    for (std::size_t j = 0; j <= i; ++j) e += stationary[3 * i + j] * xi[j];
    state_[i] = mean_[i] + sigma_[i] * e;
  }
}

Vec3 VelocityProcess::next() {
  Vec3 current;
  double xi[3];
  rng_.normals(xi);
  advance(current, xi);
  return current;
}

void VelocityProcess::generate(std::span<Vec3> out) {
  forcing_draws_.resize(3 * out.size());
  rng_.normals(forcing_draws_);
  for (std::size_t k = 0; k < out.size(); ++k) advance(out[k], &forcing_draws_[3 * k]);
}

}  // namespace synth
