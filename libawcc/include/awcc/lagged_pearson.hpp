#pragma once
// Pearson's correlation coefficient of a fixed window of x against y shifted
// by each lag of a range, from samples fed block by block (Felder's segmented
// correlation of raw voltages, METHOD.md 3; felder-program.md 3).
//
// With X = x(t0 .. t0 + B - 1) fixed and Y_k = y(t0 + k .. t0 + B - 1 + k),
//   r(k) = (sum X Y_k - sum X sum Y_k / B)
//          / sqrt((sum X^2 - (sum X)^2 / B) (sum Y_k^2 - (sum Y_k)^2 / B)),
// i.e. the coefficient with the window means, the same samples of x at every
// lag. The lagged products come from FFTs of chunks of the window (overlap
// save), the window sums of Y_k from running prefix sums; values are shifted
// by the first sample fed (r is invariant under a constant shift), so that
// the products are of the signal's swing, not of its offset, and sums are in
// long double. Memory depends on the chunk and the lag range, not on B.

#include <complex>
#include <memory>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "awcc/fft.hpp"

namespace awcc {

class LaggedPearson {
 public:
  /// The window [x_start, x_start + window) of x against y at lags
  /// [k_first, k_last]; y is read over [x_start + k_first, x_start + window + k_last).
  /// same_signal: x is y (an auto-correlation, k_first <= 0 <= k_last):
  /// x is read from y's samples and feed() ignores its x.
  LaggedPearson(std::int64_t x_start, std::int64_t window, std::int64_t k_first, std::int64_t k_last,
                FftPlanCache& plans, bool same_signal = false);

  /// Starts again with the window at x_start (same length and lags),
  /// keeping the buffers: the next segment of a segmented correlation.
  void restart(std::int64_t x_start);

  /// Feeds samples [first, first + x.size()) of both signals (x.size() ==
  /// y.size()), consecutively from wherever the caller starts; samples
  /// outside the spans above are ignored. Blocks must not skip samples the
  /// spans need.
  void feed(std::int64_t first, std::span<const double> x, std::span<const double> y);

  /// True once every sample of both spans has been fed.
  [[nodiscard]] bool complete() const;
  /// The first and one past the last sample this accumulator needs.
  [[nodiscard]] std::int64_t span_begin() const { return y_begin_; }
  [[nodiscard]] std::int64_t span_end() const { return y_end_; }

  /// r(k_first + j) for j = 0 .. k_last - k_first; NaN where X or Y_k is
  /// constant. Only when complete().
  [[nodiscard]] std::vector<double> coefficients() const;

 private:
  void run_chunks(bool final);

  std::int64_t window_, x_begin_ = 0, x_end_ = 0, k_first_, k_last_, y_begin_ = 0, y_end_ = 0;
  std::size_t lags_, chunk_;
  const FftPlan* plan_;
  FftBuffers x_fft_, y_fft_;  // x's spectrum stays while y's is made
  // x from x_next_ (next chunk start) on; y from x_next_ + k_first on.
  /// Grows the buffers without zeroing what feed() overwrites at once (the
  /// zeroing was a tenth of Felder's raw correlations' time).
  template <class T>
  struct Uninitialised : std::allocator<T> {
    template <class U>
    struct rebind {
      using other = Uninitialised<U>;
    };
    using std::allocator<T>::allocator;
    template <class U>
    void construct(U* p) noexcept {
      ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
      ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
  };
  std::vector<double, Uninitialised<double>> x_buffer_, y_buffer_;
  std::int64_t x_next_ = 0, x_fed_ = 0, y_fed_ = 0;  // next chunk start; samples fed so far up to these indices
  bool same_signal_ = false;
  bool offsets_set_ = false;
  double x_offset_ = 0.0, y_offset_ = 0.0;
  long double sx_ = 0, sxx_ = 0;          // window sums of X
  long double py_ = 0, pyy_ = 0;          // running prefix sums of y from y_begin_
  std::vector<long double> head_y_, head_yy_, tail_y_, tail_yy_;  // prefixes at x_begin + k and x_end + k
  std::vector<long double> products_;     // sum X Y_k
};

/// The same by a direct sum in long double (tests, and very short windows).
std::vector<double> lagged_pearson_naive(std::span<const double> x, std::span<const double> y, std::int64_t x_start,
                                         std::int64_t window, std::int64_t k_first, std::int64_t k_last);

}  // namespace awcc
