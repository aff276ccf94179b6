#pragma once
// The seeded generator family of the toolkit. Every consumer draws from its
// own stream, derived from (seed, stream tag) or (seed, index), and consumes
// it in an order fixed by the computation, never by chunk sizes or threads:
// the same seed gives the same numbers however the work is cut.
//  - splitmix64: turns a seed into well-mixed 64-bit values (Steele et al.
//    2014); mix64 is its output function applied to one value.
//  - derive_seed(seed, i): the seed of item i of a study (run, tree).
//  - Rng: xoshiro256** (Blackman and Vigna) seeded through splitmix64, with a
//    Marsaglia polar normal generator.
//  - SplitMix64: the small generator of one forest tree, with unbiased
//    integers below n.

#include <cmath>
#include <concepts>
#include <cstdint>
#include <type_traits>

namespace awcc {

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

  /// Standard normal.
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform() - 1.0;
      v = 2.0 * uniform() - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double m = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * m;
    has_spare_ = true;
    return u * m;
  }

  /// Exponential with unit mean.
  double exponential() { return -std::log(uniform_open_low()); }

 private:
  static constexpr std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4]{};
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace awcc
