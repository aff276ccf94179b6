#pragma once
// Random sequential placement of a particle on the periodic cross-section of
// the control volume (synth/synthesiser.hpp, "Dense placement"): the
// attempts of the synthesiser's placement, drawn and tested in batches.
//
// The rule (METHOD 5.2, "retry a few lateral positions"): up to n attempts,
// each a position uniform on the L_y x L_z cross-section, the first one that
// overlaps no neighbour wins. Seen from the entry plane, a neighbour at
// streamwise separation s_x (sphere-mapped) forbids the disc of squared
// radius (r^2 - s_x^2) lf^2 (lf the lateral semi-axis factor) around its
// lateral centre, under minimum image. So, with p the free part of the
// cross-section, a call succeeds with probability 1 - (1 - p)^n, its
// position uniform on the free part, and after k - 1 covered attempts the
// k-th is free with probability p: a truncated geometric count. A failed
// call's n positions are independent and uniform on the covered part.
//
// Drawn in batches: each attempt is one 64-bit draw whose halves are the
// 32-bit fractions of y and z (a 7 mm cross-section at 2^-32 is a
// resolution of 2 pm), and every attempt of a batch is tested against the
// discs together, without a branch per disc (the lanes vectorise), until
// every lane is covered or every disc tested; the first free lane is then
// found once. Attempts drawn past the winner, or past n, are ignored. That
// is the same distribution as testing one attempt at a time (the attempts
// are i.i.d. and the winner is the first free one in draw order), without
// the mispredicted branch of every attempt and every disc. The stream
// consumed depends on the outcome only, never on threads or chunk sizes.

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define SYNTH_PLACEMENT_AVX2 1
#endif

#include "awcc/random.hpp"

namespace synth {

class LateralPlacement {
 public:
  /// Attempts drawn and tested together.
  static constexpr int batch = 8;

  /// The result of one call: `attempts` positions count (the ones drawn up to
  /// the winner, or all n), y(i), z(i) for i < attempts; when placed the
  /// winner is the last of them.
  struct Outcome {
    bool placed = false;
    int attempts = 0;
  };

  LateralPlacement(double length_y, double length_z) : ly_(length_y), lz_(length_z) { allow_avx2(true); }

  /// Whether the attempts may be tested with AVX2 where the CPU has it (the
  /// default); off, with SSE2. The same bits either way: this exists for
  /// the test that shows it. Returns whether AVX2 is used.
  bool allow_avx2(bool allowed) {
#if defined(SYNTH_PLACEMENT_AVX2)
    avx2_ = allowed && __builtin_cpu_supports("avx2");
#else
    (void)allowed;
    avx2_ = false;
#endif
    return avx2_;
  }

  void clear() {
    cy_.clear();
    cz_.clear();
    rho2_.clear();
  }

  /// A forbidden disc: centre (y, z) anywhere (reduced here to the tile
  /// [-L/2, L/2]), squared radius in lateral units.
  void add_disc(double y, double z, double radius2) {
    cy_.push_back(reduce(y, ly_));
    cz_.push_back(reduce(z, lz_));
    rho2_.push_back(radius2);
  }

  [[nodiscard]] std::size_t discs() const { return cy_.size(); }

  /// Squared minimum-image distance from (y, z) to disc k's centre, for
  /// (y, z) in the tile: the separations lie in (-L, L), so the nearer of
  /// |s| and L - |s| is the nearest image.
  [[nodiscard]] double distance2(std::size_t k, double y, double z) const {
    double dy = std::fabs(y - cy_[k]);
    double dz = std::fabs(z - cz_[k]);
    dy = std::min(dy, ly_ - dy);
    dz = std::min(dz, lz_ - dz);
    return dy * dy + dz * dz;
  }

  [[nodiscard]] double y(int i) const { return ys_[static_cast<std::size_t>(i)]; }
  [[nodiscard]] double z(int i) const { return zs_[static_cast<std::size_t>(i)]; }

  /// Up to n attempts (n >= 1) from rng.
  Outcome place(awcc::Rng& rng, int n) {
    const auto rounded = static_cast<std::size_t>((n + batch - 1) / batch) * std::size_t{batch};
    if (ys_.size() < rounded) {
      ys_.resize(rounded);
      zs_.resize(rounded);
    }
    for (int first = 0; first < n; first += batch) {
      const int lanes = std::min(batch, n - first);
      const unsigned covered = draw_batch(rng, ys_.data() + first, zs_.data() + first, lanes);
      const unsigned free = ~covered & ((1u << lanes) - 1u);
      if (free) return {true, first + std::countr_zero(free) + 1};
    }
    return {false, n};
  }

 private:
  // A lane is covered once one disc covers it, so the test of a batch stops
  // when its lanes are all covered: whether a lane is covered does not
  // depend on the discs not yet tested, so the outcome and the draws are
  // the same bits. In a dense flow most batches end so (c 0.42, log-normal
  // sizes at sd 0.6, aspect 0.5: 85 % of batches covered throughout, every
  // lane after 45 of a batch's 121 discs on average), and the synthesis
  // took 19 % less time. Testing the larger discs first would stop after 30,
  // but ordering them cost what it saved. The look at the lanes costs about
  // one disc's test, so it comes every few discs (2, 4 and 8 measured alike).
  static constexpr std::size_t look_every = 4;

  // Draws a batch into y, z and returns the lanes covered (bit i: lane i is
  // inside a disc), exactly for the first `lanes` (the others may be left
  // uncovered once those are covered: the caller ignores them). A lane's
  // margin is the least of d^2 - rho^2 over the discs, negative once inside
  // one (the sign of a difference of doubles is exact, so this is d^2 <
  // rho^2). Two lanes at a time where SSE2 is there (every x86-64; GCC keeps
  // the scalar loop scalar), with the draws kept in registers (a pair of
  // lanes read back from two scalar stores stalls). The same operations in
  // the same order either way: the same bits.
  unsigned draw_batch(awcc::Rng& rng, double* y, double* z, int lanes) const {
    const std::size_t count = cy_.size();
    const unsigned wanted = (1u << lanes) - 1u;
#if defined(SYNTH_PLACEMENT_AVX2)
    if (avx2_) return draw_batch_avx2(rng, y, z, wanted);
#endif
#if defined(__SSE2__)
    const __m128d sign = _mm_set1_pd(-0.0), ly = _mm_set1_pd(ly_), lz = _mm_set1_pd(lz_);
    const __m128d one = _mm_set1_pd(1.0), half = _mm_set1_pd(0.5);
    const __m128i exponent = _mm_set1_epi64x(0x3ff0000000000000ll);
    __m128d yv[batch / 2], zv[batch / 2], m[batch / 2];
    for (int h = 0; h < batch / 2; ++h) {
      const std::uint64_t r0 = rng.next(), r1 = rng.next();
      const __m128i r = _mm_set_epi64x(static_cast<long long>(r1), static_cast<long long>(r0));
      const __m128i high = _mm_srli_epi64(r, 32);
      const __m128i low = _mm_srli_epi64(_mm_slli_epi64(r, 32), 32);
      const __m128d fy = _mm_sub_pd(_mm_castsi128_pd(_mm_or_si128(_mm_slli_epi64(high, 20), exponent)), one);
      const __m128d fz = _mm_sub_pd(_mm_castsi128_pd(_mm_or_si128(_mm_slli_epi64(low, 20), exponent)), one);
      yv[h] = _mm_mul_pd(_mm_sub_pd(fy, half), ly);
      zv[h] = _mm_mul_pd(_mm_sub_pd(fz, half), lz);
      _mm_storeu_pd(y + static_cast<std::ptrdiff_t>(2 * h), yv[h]);
      _mm_storeu_pd(z + static_cast<std::ptrdiff_t>(2 * h), zv[h]);
      m[h] = _mm_set1_pd(std::numeric_limits<double>::infinity());
    }
    auto covered = [&] {
      unsigned bits = 0;
      for (int h = 0; h < batch / 2; ++h) {
        bits |= static_cast<unsigned>(_mm_movemask_pd(_mm_cmplt_pd(m[h], _mm_setzero_pd()))) << (2 * h);
      }
      return bits;
    };
    for (std::size_t k = 0; k < count;) {
      for (const std::size_t end = std::min(count, k + look_every); k < end; ++k) {
        const __m128d cy = _mm_set1_pd(cy_[k]), cz = _mm_set1_pd(cz_[k]), rho2 = _mm_set1_pd(rho2_[k]);
        for (int h = 0; h < batch / 2; ++h) {
          __m128d dy = _mm_andnot_pd(sign, _mm_sub_pd(yv[h], cy));
          __m128d dz = _mm_andnot_pd(sign, _mm_sub_pd(zv[h], cz));
          dy = _mm_min_pd(_mm_sub_pd(ly, dy), dy);  // (ly - dy < dy) ? ly - dy : dy, as std::min
          dz = _mm_min_pd(_mm_sub_pd(lz, dz), dz);
          const __m128d d2 = _mm_add_pd(_mm_mul_pd(dy, dy), _mm_mul_pd(dz, dz));
          m[h] = _mm_min_pd(_mm_sub_pd(d2, rho2), m[h]);
        }
      }
      if ((covered() & wanted) == wanted) break;
    }
    return covered();
#else
    for (int i = 0; i < batch; ++i) {
      const std::uint64_t r = rng.next();
      y[i] = (fraction(r >> 32) - 0.5) * ly_;
      z[i] = (fraction(r & 0xffffffffu) - 0.5) * lz_;
    }
    unsigned covered = 0;
    for (int i = 0; i < batch; ++i) {
      double margin = std::numeric_limits<double>::infinity();
      for (std::size_t k = 0; k < count; ++k) {
        double dy = std::fabs(y[i] - cy_[k]);
        double dz = std::fabs(z[i] - cz_[k]);
        dy = std::min(dy, ly_ - dy);
        dz = std::min(dz, lz_ - dz);
        margin = std::min(margin, dy * dy + dz * dz - rho2_[k]);
      }
      covered |= static_cast<unsigned>(margin < 0.0) << i;
    }
    (void)wanted;
    return covered;
#endif
  }

#if defined(SYNTH_PLACEMENT_AVX2)
  // draw_batch four lanes at a time, where the CPU has AVX2 (checked once,
  // at run time): half the instructions a disc. The same operations on each
  // lane in the same order (AVX2 alone brings no fused multiply-add, so
  // none is contracted): the same bits as the SSE2 and scalar loops
  // (LateralPlacement.AvxAndSseGiveTheSameBits).
  __attribute__((target("avx2"))) unsigned draw_batch_avx2(awcc::Rng& rng, double* y, double* z,
                                                          unsigned wanted) const {
    const std::size_t count = cy_.size();
    const __m256d sign = _mm256_set1_pd(-0.0), ly = _mm256_set1_pd(ly_), lz = _mm256_set1_pd(lz_);
    const __m256d one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5);
    const __m256i exponent = _mm256_set1_epi64x(0x3ff0000000000000ll);
    __m256d yv[batch / 4], zv[batch / 4], m[batch / 4];
    for (int h = 0; h < batch / 4; ++h) {
      const std::uint64_t r0 = rng.next(), r1 = rng.next(), r2 = rng.next(), r3 = rng.next();
      const __m256i r = _mm256_set_epi64x(static_cast<long long>(r3), static_cast<long long>(r2),
                                          static_cast<long long>(r1), static_cast<long long>(r0));
      const __m256i high = _mm256_srli_epi64(r, 32);
      const __m256i low = _mm256_srli_epi64(_mm256_slli_epi64(r, 32), 32);
      const __m256d fy = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(_mm256_slli_epi64(high, 20), exponent)), one);
      const __m256d fz = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(_mm256_slli_epi64(low, 20), exponent)), one);
      yv[h] = _mm256_mul_pd(_mm256_sub_pd(fy, half), ly);
      zv[h] = _mm256_mul_pd(_mm256_sub_pd(fz, half), lz);
      _mm256_storeu_pd(y + static_cast<std::ptrdiff_t>(4 * h), yv[h]);
      _mm256_storeu_pd(z + static_cast<std::ptrdiff_t>(4 * h), zv[h]);
      m[h] = _mm256_set1_pd(std::numeric_limits<double>::infinity());
    }
    auto covered = [&]() __attribute__((target("avx2"))) {
      unsigned bits = 0;
      for (int h = 0; h < batch / 4; ++h) {
        bits |= static_cast<unsigned>(_mm256_movemask_pd(_mm256_cmp_pd(m[h], _mm256_setzero_pd(), _CMP_LT_OQ)))
                << (4 * h);
      }
      return bits;
    };
    for (std::size_t k = 0; k < count;) {
      for (const std::size_t end = std::min(count, k + look_every); k < end; ++k) {
        const __m256d cy = _mm256_set1_pd(cy_[k]), cz = _mm256_set1_pd(cz_[k]), rho2 = _mm256_set1_pd(rho2_[k]);
        for (int h = 0; h < batch / 4; ++h) {
          __m256d dy = _mm256_andnot_pd(sign, _mm256_sub_pd(yv[h], cy));
          __m256d dz = _mm256_andnot_pd(sign, _mm256_sub_pd(zv[h], cz));
          dy = _mm256_min_pd(_mm256_sub_pd(ly, dy), dy);
          dz = _mm256_min_pd(_mm256_sub_pd(lz, dz), dz);
          const __m256d d2 = _mm256_add_pd(_mm256_mul_pd(dy, dy), _mm256_mul_pd(dz, dz));
          m[h] = _mm256_min_pd(_mm256_sub_pd(d2, rho2), m[h]);
        }
      }
      if ((covered() & wanted) == wanted) break;
    }
    return covered();
  }
#endif

  // v reduced to [-L/2, L/2] by whole periods. A centre is an entry in the
  // tile plus the drift since, rarely a period: one shift each way without
  // a branch, and a division only beyond that.
  static double reduce(double v, double length) {
    const double half = 0.5 * length;
    const double above = length * static_cast<double>(v > half);
    const double below = length * static_cast<double>(v < -half);
    v = (v - above) + below;
    if (v > half || v < -half) [[unlikely]] v -= length * std::nearbyint(v / length);
    return v;
  }

  // A 32-bit integer as a fraction in [0, 1): its bits as the top of a
  // mantissa of a double in [1, 2), minus 1 (exact).
  static double fraction(std::uint64_t bits32) {
    return std::bit_cast<double>((bits32 << 20) | 0x3ff0000000000000ull) - 1.0;
  }

  double ly_, lz_;
  bool avx2_ = false;  // draw_batch_avx2
  std::vector<double> cy_, cz_, rho2_;
  std::vector<double> ys_, zs_;
};

}  // namespace synth
