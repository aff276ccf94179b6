#pragma once
// Random streams of the synthetic probe. Every consumer (velocity forcing,
// bubble arrivals and positions, voltage noise) draws from its own stream,
// seeded from the scene seed and a fixed stream tag, and consumes it in an
// order fixed by the physics, never by chunk sizes or threads: the same seed
// gives the same numbers however the work is cut.

#include <cmath>
#include <cstdint>
#include <limits>

namespace synth {

/// SplitMix64: turns (seed, tag) into well-mixed 64-bit seeds.
constexpr std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

enum class Stream : std::uint64_t { velocity = 1, bubbles = 2, noise = 3 };

/// xoshiro256** (Blackman and Vigna), with a Marsaglia polar normal generator.
class Rng {
 public:
  Rng(std::uint64_t seed, Stream stream) {
    std::uint64_t state = seed ^ (static_cast<std::uint64_t>(stream) * 0xD1B54A32D192ED03ull);
    for (auto& s : s_) s = splitmix64(state);
  }

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

}  // namespace synth
