#pragma once
// The seeded generator family of the toolkit. Every consumer draws from its
// own stream, derived from (seed, stream tag) or (seed, index), and consumes
// it in an order fixed by the computation, never by chunk sizes or threads:
// the same seed gives the same numbers however the work is cut.
//  - splitmix64: turns a seed into well-mixed 64-bit values (Steele et al.
//    2014); mix64 is its output function applied to one value.
//  - derive_seed(seed, i): the seed of item i of a study (run, tree).
//  - Rng: xoshiro256** (Blackman and Vigna) seeded through splitmix64, with
//    normals by the ziggurat method (Marsaglia and Tsang 2000, 256 layers;
//    layer, sign and abscissa from disjoint bits of one draw, as Doornik 2005
//    advises), exact: the layers, the wedges and the tail together are the
//    normal density, no approximation.
//  - generator_version: which streams a seed gives (below). Outputs of the
//    synthetic probe record it, so rows of two versions are never mixed unsaid.
//  - SplitMix64: the small generator of one forest tree, with unbiased
//    integers below n.

#include <array>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <numbers>
#include <span>
#include <type_traits>

namespace awcc {

/// The version of the seeded streams: the same seed gives the same numbers
/// within a version, whatever the thread count or chunk size.
///  1: polar normals, placement by rejection (pdp up to issue 31).
///  2: ziggurat normals drawn in blocks, placement without rejection loops (issue 32).
inline constexpr int generator_version = 2;

constexpr std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// splitmix64 of a copy of z: a hash of one 64-bit value.
constexpr std::uint64_t mix64(std::uint64_t z) { return splitmix64(z); }

/// Seed of item `index` of a study seeded `seed` (independent of order and
/// threads); a non-negative int64, so that it reads back from any file.
constexpr std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t state = seed * 0x9E3779B97F4A7C15ull + index;
  splitmix64(state);
  return splitmix64(state) >> 1;
}

struct SplitMix64 {
  std::uint64_t state = 0;
  constexpr std::uint64_t next() { return splitmix64(state); }
  /// Uniform in [0, n) without modulo bias (the short top end is redrawn).
  constexpr std::uint64_t below(std::uint64_t n) {
    const std::uint64_t reject_below = (0 - n) % n;
    for (;;) {
      const std::uint64_t r = next();
      if (r >= reject_below) return r % n;
    }
  }
};

/// The ziggurat of the standard normal density f(x) = exp(-x^2/2) (the
/// unnormalised one; the constant cancels): 256 layers of equal area V, x[0]
/// the base layer's width V / f(R) (its rectangle and the tail beyond R),
/// x[1] = R, x[i+1] from x[i] (f(x[i+1]) - f(x[i])) = V, x[256] = 0. R is
/// Marsaglia and Tsang's, for which the top layer closes, x[255] (1 - f(x[255]))
/// = V, to 1.4e-13 relative (tested).
struct ZigguratTables {
  static constexpr double R = 3.6541528853610088;      // rightmost layer edge
  double V = 0.0;  // area of each layer: R f(R) + the tail's integral, so that the top layer closes
  std::array<double, 257> x{};
  std::array<double, 257> f{};  // f(x[i])
};

inline const ZigguratTables& ziggurat_tables() {
  static const ZigguratTables tables = [] {
    ZigguratTables t;
    const double R = ZigguratTables::R;
    t.V = R * std::exp(-0.5 * R * R) + std::sqrt(0.5 * std::numbers::pi) * std::erfc(R / std::numbers::sqrt2);
    const double V = t.V;
    t.x[0] = V / std::exp(-0.5 * R * R);
    t.x[1] = R;
    for (std::size_t i = 1; i < 255; ++i) {
      t.x[i + 1] = std::sqrt(-2.0 * std::log(V / t.x[i] + std::exp(-0.5 * t.x[i] * t.x[i])));
    }
    t.x[256] = 0.0;
    for (std::size_t i = 0; i < 257; ++i) t.f[i] = std::exp(-0.5 * t.x[i] * t.x[i]);
    return t;
  }();
  return tables;
}

class Rng {
 public:
  Rng(std::uint64_t seed, std::uint64_t stream) {
    std::uint64_t state = seed ^ (stream * 0xD1B54A32D192ED03ull);
    for (auto& s : s_) s = splitmix64(state);
  }
  /// A stream named by an enumeration of the consumer's (e.g. synth::Stream).
  template <class Tag>
    requires std::is_enum_v<Tag>
  Rng(std::uint64_t seed, Tag stream) : Rng(seed, static_cast<std::uint64_t>(stream)) {}

  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  /// Uniform on [0, 1), 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  /// Uniform on (0, 1]: safe under a logarithm.
  double uniform_open_low() { return (static_cast<double>(next() >> 11) + 1.0) * 0x1.0p-53; }

  /// Standard normal (ziggurat; one 64-bit draw on the fast path, 98.8 %).
  double normal() {
    for (;;) {
      const std::uint64_t r = next();
      const std::size_t layer = r & 0xFF;
      // The sign by flipping the sign bit: the same number as -1 or +1 times
      // z, without a branch that goes each way half the time (10 % of the
      // synthesis, in mispredictions, when it was one).
      const std::uint64_t sign_bit = (r & 0x100) << 55;
      auto with_sign = [sign_bit](double v) { return std::bit_cast<double>(std::bit_cast<std::uint64_t>(v) ^ sign_bit); };
      const double z = static_cast<double>(r >> 11) * 0x1.0p-53 * zig_->x[layer];
      if (z < zig_->x[layer + 1]) return with_sign(z);  // inside the layer's rectangle under the next layer
      if (layer == 0) return with_sign(tail());
      // The wedge between the rectangle and the density: accept under f(z).
      const double y = zig_->f[layer] + uniform() * (zig_->f[layer + 1] - zig_->f[layer]);
      if (y < std::exp(-0.5 * z * z)) return with_sign(z);
    }
  }

  /// Standard normals into `out`, the same numbers as that many normal() calls in order.
  void normals(std::span<double> out) {
    for (double& z : out) z = normal();
  }

  /// Exponential with unit mean.
  double exponential() { return -std::log(uniform_open_low()); }

 private:
  static constexpr std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

  // Beyond R: Marsaglia's tail method (exact for the normal tail).
  double tail() {
    double a, b;
    do {
      a = -std::log(uniform_open_low()) / ZigguratTables::R;
      b = -std::log(uniform_open_low());
    } while (2.0 * b < a * a);
    return ZigguratTables::R + a;
  }

  std::uint64_t s_[4]{};
  const ZigguratTables* zig_ = &ziggurat_tables();
};

}  // namespace awcc
