#pragma once
// FFT plans for correlation. A plan is built once for its size and used const
// (FFTW's execute is thread-safe, its planner is not); the arrays it transforms
// are the caller's scratch (FftBuffers), so one plan serves any number of
// buffers and threads. A cache builds one plan per size on first use. Sizes are
// rounded up to 2^k, 3 2^k or 5 2^k: fast for FFTW, and few enough that windows
// of similar lengths share plans.

#include <complex>
#include <cstddef>
#include <map>
#include <memory>
#include <span>

namespace awcc {

/// Smallest n >= minimum of the form 2^k, 3 2^k or 5 2^k.
std::size_t fast_fft_size(std::size_t minimum);

/// The arrays of one transform of size n: n real values and n / 2 + 1 complex
/// ones, aligned as FFTW's plans expect. Scratch: owned by whoever transforms.
class FftBuffers {
 public:
  FftBuffers() = default;
  explicit FftBuffers(std::size_t n) { resize(n); }
  ~FftBuffers();
  FftBuffers(FftBuffers&& other) noexcept;
  FftBuffers& operator=(FftBuffers&& other) noexcept;
  FftBuffers(const FftBuffers&) = delete;
  FftBuffers& operator=(const FftBuffers&) = delete;

  /// Sized for transforms of size n; memory is reallocated only to grow.
  void resize(std::size_t n);
  [[nodiscard]] std::size_t size() const { return n_; }
  /// Time-domain values (n).
  [[nodiscard]] std::span<double> real() { return {real_, n_}; }
  /// Spectrum (n / 2 + 1 values).
  [[nodiscard]] std::span<std::complex<double>> spectrum() {
    return {reinterpret_cast<std::complex<double>*>(spectrum_), n_ == 0 ? 0 : n_ / 2 + 1};
  }

 private:
  void release();
  std::size_t n_ = 0, capacity_ = 0;
  double* real_ = nullptr;
  void* spectrum_ = nullptr;
};

/// Real-to-complex forward and complex-to-real inverse transforms of size n,
/// applied to buffers of that size.
class FftPlan {
 public:
  explicit FftPlan(std::size_t n);
  ~FftPlan();
  FftPlan(const FftPlan&) = delete;
  FftPlan& operator=(const FftPlan&) = delete;

  [[nodiscard]] std::size_t size() const { return n_; }
  void forward(FftBuffers& buffers) const;  ///< real() -> spectrum()
  void inverse(FftBuffers& buffers) const;  ///< spectrum() -> real(), unnormalised (scaled by n); spectrum() is lost

 private:
  std::size_t n_;
  void* forward_ = nullptr;
  void* inverse_ = nullptr;
};

/// One plan per size, built on first use and kept for the cache's life (not
/// itself thread-safe: one per thread, or filled before the threads start).
class FftPlanCache {
 public:
  const FftPlan& get(std::size_t n);

 private:
  std::map<std::size_t, std::unique_ptr<const FftPlan>> plans_;
};

}  // namespace awcc
