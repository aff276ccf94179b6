// The per-window correlation and filter chain on arbitrary sample blocks:
// voltages through the FFT path, and the bits as binary signals through both
// exact paths, which must agree (a differential check).
#include "awcc/detail/awcc_steps.hpp"
#include <cmath>
#include <cstring>
#include <vector>

#include "awcc/awcc.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 4) return 0;
  const std::size_t n = std::min<std::size_t>((size - 2) / 2, 4096);
  if (n < 2) return 0;
  // Voltages: int8 pairs, any values.
  std::vector<double> x(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = static_cast<std::int8_t>(data[2 + 2 * i]);
    y[i] = static_cast<std::int8_t>(data[3 + 2 * i]);
  }
  awcc::AwccWorkspace plans;
  awcc::AwccOptions o;
  o.subsample = data[0] & 1 ? awcc::Subsample::parabolic : awcc::Subsample::none;
  o.prominence_fraction = (data[1] % 11) / 10.0;
  const auto k = static_cast<std::int64_t>(n) - 1;
  const auto r = awcc::detail::window_correlation_fft(x, y, -k, k, plans);
  awcc::AwccWindow w;
  w.length = static_cast<std::int64_t>(n);
  w.duration = static_cast<double>(n);
  awcc::detail::analyse_window(w, r, -k, 1.0, 1.0, o, plans);
  if (!r.empty() && !(std::isfinite(w.r12_max) && std::isfinite(w.spr) && std::isfinite(w.velocity))) __builtin_trap();
  // Binary signals from the low bits: both exact paths agree.
  std::vector<std::uint8_t> bx(n), by(n);
  for (std::size_t i = 0; i < n; ++i) {
    bx[i] = data[2 + 2 * i] & 1;
    by[i] = data[3 + 2 * i] & 1;
  }
  const auto sx = awcc::from_dense(bx, 1.0), sy = awcc::from_dense(by, 1.0);
  const auto pieces = awcc::detail::window_correlation_intervals(sx, sy, 0, static_cast<std::int64_t>(n), -k, k, plans);
  std::vector<double> fx(bx.begin(), bx.end()), fy(by.begin(), by.end());
  const auto fft = awcc::detail::window_correlation_fft(fx, fy, -k, k, plans);
  if (pieces.size() != fft.size()) __builtin_trap();
  for (std::size_t i = 0; i < fft.size(); ++i)
    if (std::fabs(pieces[i] - fft[i]) > 1e-8) __builtin_trap();
  // The whole chain on the binary pair.
  awcc::AwccOptions chain;
  chain.np = 1 + data[0] % 5;
  const auto result = awcc::awcc(sx, sy, 1.0, chain);
  if (!std::isfinite(result.velocity) || !std::isfinite(result.turbulence_intensity)) __builtin_trap();
  return 0;
}
