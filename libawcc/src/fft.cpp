#include "awcc/fft.hpp"

#include <fftw3.h>
#include <algorithm>
#include <mutex>
#include <new>
#include <stdexcept>
#include <utility>

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

FftBuffers::~FftBuffers() { release(); }

FftBuffers::FftBuffers(FftBuffers&& other) noexcept
    : n_(std::exchange(other.n_, 0)), capacity_(std::exchange(other.capacity_, 0)),
      real_(std::exchange(other.real_, nullptr)), spectrum_(std::exchange(other.spectrum_, nullptr)) {}

FftBuffers& FftBuffers::operator=(FftBuffers&& other) noexcept {
  if (this != &other) {
    release();
    n_ = std::exchange(other.n_, 0);
    capacity_ = std::exchange(other.capacity_, 0);
    real_ = std::exchange(other.real_, nullptr);
    spectrum_ = std::exchange(other.spectrum_, nullptr);
  }
  return *this;
}

void FftBuffers::release() {
  fftw_free(real_);
  fftw_free(spectrum_);
  real_ = nullptr;
  spectrum_ = nullptr;
  n_ = capacity_ = 0;
}

void FftBuffers::resize(std::size_t n) {
  if (n > capacity_) {
    release();
    // fftw_malloc's alignment is the one the plans were made for (FftPlan).
    real_ = fftw_alloc_real(n);
    spectrum_ = fftw_alloc_complex(n / 2 + 1);
    if (!real_ || !spectrum_) {
      release();
      throw std::bad_alloc();
    }
    capacity_ = n;
  }
  n_ = n;
}

FftPlan::FftPlan(std::size_t n) : n_(n) {
  if (n == 0) throw std::invalid_argument("FftPlan: a transform of size 0");
  // Planned on arrays of the alignment FftBuffers has: FFTW's new-array
  // execute then runs the same code on any of them. FFTW_ESTIMATE does not
  // touch the arrays, and gives the same plan whenever it is made.
  FftBuffers arrays(n);
  std::lock_guard lock(planner_mutex());
  const int size = static_cast<int>(n);
  auto* real = arrays.real().data();
  auto* spectrum = reinterpret_cast<fftw_complex*>(arrays.spectrum().data());
  forward_ = fftw_plan_dft_r2c_1d(size, real, spectrum, FFTW_ESTIMATE);
  inverse_ = fftw_plan_dft_c2r_1d(size, spectrum, real, FFTW_ESTIMATE);
  if (!forward_ || !inverse_) {
    if (forward_) fftw_destroy_plan(static_cast<fftw_plan>(forward_));
    if (inverse_) fftw_destroy_plan(static_cast<fftw_plan>(inverse_));
    throw std::logic_error("FftPlan: FFTW made no plan");
  }
}

FftPlan::~FftPlan() {
  std::lock_guard lock(planner_mutex());
  if (forward_) fftw_destroy_plan(static_cast<fftw_plan>(forward_));
  if (inverse_) fftw_destroy_plan(static_cast<fftw_plan>(inverse_));
}

namespace {
void check_size(const FftPlan& plan, const FftBuffers& buffers) {
  if (buffers.size() != plan.size()) throw std::logic_error("FftPlan: buffers of another size");
}
}  // namespace

void FftPlan::forward(FftBuffers& buffers) const {
  check_size(*this, buffers);
  fftw_execute_dft_r2c(static_cast<fftw_plan>(forward_), buffers.real().data(),
                       reinterpret_cast<fftw_complex*>(buffers.spectrum().data()));
}

void FftPlan::inverse(FftBuffers& buffers) const {
  check_size(*this, buffers);
  fftw_execute_dft_c2r(static_cast<fftw_plan>(inverse_), reinterpret_cast<fftw_complex*>(buffers.spectrum().data()),
                       buffers.real().data());
}

const FftPlan& FftPlanCache::get(std::size_t n) {
  auto& slot = plans_[n];
  if (!slot) slot = std::make_unique<const FftPlan>(n);
  return *slot;
}

}  // namespace awcc
