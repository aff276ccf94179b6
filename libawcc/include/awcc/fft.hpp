#pragma once
// FFT plans for correlation: a plan object owns its FFTW plans and scratch
// buffers and is reused for every transform of its size; a cache hands out one
// plan per size. Sizes are rounded up to 2^k, 3 2^k or 5 2^k: fast for FFTW,
// and few enough that windows of similar lengths share plans.

#include <complex>
#include <cstddef>
#include <map>
#include <memory>
#include <span>
#include <utility>

namespace awcc {

/// Smallest n >= minimum of the form 2^k, 3 2^k or 5 2^k.
std::size_t fast_fft_size(std::size_t minimum);

/// Real-to-complex forward and complex-to-real inverse transforms of size n.
class FftPlan {
 public:
  explicit FftPlan(std::size_t n);
  ~FftPlan();
  FftPlan(const FftPlan&) = delete;
  FftPlan& operator=(const FftPlan&) = delete;

  [[nodiscard]] std::size_t size() const { return n_; }
  /// Time-domain buffer (n values).
  [[nodiscard]] std::span<double> real() { return {real_, n_}; }
  /// Spectrum buffer (n / 2 + 1 values).
  [[nodiscard]] std::span<std::complex<double>> spectrum() {
    return {reinterpret_cast<std::complex<double>*>(spectrum_), n_ / 2 + 1};
  }
  void forward();  ///< real() -> spectrum()
  void inverse();  ///< spectrum() -> real(), unnormalised (scaled by n)

 private:
  std::size_t n_;
  double* real_ = nullptr;
  void* spectrum_ = nullptr;
  void* forward_ = nullptr;
  void* inverse_ = nullptr;
};

/// One plan per size, created on first use (plan creation is serialised:
/// FFTW's planner is not thread-safe).
class FftPlanCache {
 public:
  /// The plan of size n; `instance` > 0 gives another plan of that size,
  /// for transforms whose results must coexist (two spectra at once).
  FftPlan& get(std::size_t n, int instance = 0);

 private:
  std::map<std::pair<std::size_t, int>, std::unique_ptr<FftPlan>> plans_;
};

}  // namespace awcc
