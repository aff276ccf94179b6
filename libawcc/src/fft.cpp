#include "awcc/fft.hpp"

#include <fftw3.h>
#include <algorithm>
#include <mutex>
#include <new>

namespace awcc {
namespace {
std::mutex& planner_mutex() {
  static std::mutex m;
  return m;
}
}  // namespace

std::size_t fast_fft_size(std::size_t minimum) {
  // 2^k, 3 2^k or 5 2^k: fast transforms, and few distinct sizes, so that
  // the plans of a cache are reused across windows of similar lengths.
  std::size_t best = 1;
  while (best < minimum) best *= 2;
  for (std::size_t odd : {3u, 5u}) {
    std::size_t n = odd;
    while (n < minimum) n *= 2;
    best = std::min(best, n);
  }
  return best;
}

FftPlan::FftPlan(std::size_t n) : n_(n) {
  std::lock_guard lock(planner_mutex());
  real_ = fftw_alloc_real(n);
  spectrum_ = fftw_alloc_complex(n / 2 + 1);
  if (!real_ || !spectrum_) throw std::bad_alloc();
  const int size = static_cast<int>(n);
  forward_ = fftw_plan_dft_r2c_1d(size, real_, static_cast<fftw_complex*>(spectrum_), FFTW_ESTIMATE);
  inverse_ = fftw_plan_dft_c2r_1d(size, static_cast<fftw_complex*>(spectrum_), real_, FFTW_ESTIMATE);
}

FftPlan::~FftPlan() {
  std::lock_guard lock(planner_mutex());
  fftw_destroy_plan(static_cast<fftw_plan>(forward_));
  fftw_destroy_plan(static_cast<fftw_plan>(inverse_));
  fftw_free(real_);
  fftw_free(spectrum_);
}

void FftPlan::forward() { fftw_execute(static_cast<fftw_plan>(forward_)); }
void FftPlan::inverse() { fftw_execute(static_cast<fftw_plan>(inverse_)); }

FftPlan& FftPlanCache::get(std::size_t n, int instance) {
  auto& slot = plans_[{n, instance}];
  if (!slot) slot = std::make_unique<FftPlan>(n);
  return *slot;
}

}  // namespace awcc
