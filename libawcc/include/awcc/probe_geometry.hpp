#pragma once
// The geometry of a multi-tip probe (METHOD 11.3-11.5): the tips' positions,
// the leading tip 0, the vectors S_0k from it to each trailing tip k, their
// lengths |S_0k| and direction cosines c_0k = S_0k / |S_0k|, and every
// combination of three trailing tips with its conditioning.
//
// Conditioning of a combination: |det A_0|, A_0 the 3x3 matrix of rows c_0k.
// It is the volume of the parallelepiped of three unit vectors, in [0, 1]
// (1: mutually orthogonal; 0: in one plane with tip 0), and it does not
// depend on the tips' spacing, only on their directions from tip 0. It bounds
// how much the solvers amplify timing errors: with singular values s1 >= s2
// >= s3 of A_0, s1^2 + s2^2 + s3^2 = 3 (unit rows) gives s1 s2 <= 3/2, so
// s3 = |det A_0| / (s1 s2) >= (2/3) |det A_0| and ||A_0^-1|| <= 1.5 / |det A_0|:
// a lag error dt_k / |S_0k| (a dual tip's relative error) becomes an error of
// w = V / |V|^2 at most 1.5 / |det A_0| times larger.

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "awcc/validation.hpp"

namespace awcc {

using Vec3 = std::array<double, 3>;

/// A combination of three trailing tips, with what every bubble's solution
/// through it reuses: the rows c_0k and S_0k, their inverses (the solvers'
/// Cramer quotients det A_0j / det A_0 are the entries of A_0^-1 b) and the
/// conditioning.
struct TipCombination {
  std::array<std::size_t, 3> trailing{};  ///< positions in ProbeGeometry::trailing_tips()
  std::array<Vec3, 3> cosines{};          ///< rows of A_0: c_0k, -
  std::array<double, 3> lengths{};        ///< |S_0k|, m
  double det_a0 = 0.0;                    ///< det A_0, -
  std::array<Vec3, 3> inverse_cosines{};  ///< A_0^-1 (zero when det A_0 = 0)
  std::array<Vec3, 3> inverse_offsets{};  ///< S^-1, rows S_0k (Tian et al. 2015), 1/m
  [[nodiscard]] double conditioning() const;  ///< |det A_0|, in [0, 1]
};

class ProbeGeometry {
 public:
  ProbeGeometry() = default;
  /// Tip positions in metres, x streamwise (the order is the tips' numbering,
  /// 0 first, as a recording's channels and the `tips` option list them). The
  /// leading tip: `leading` when given, else the most upstream tip (smallest
  /// x); a tie for it is refused by check(). Never throws: check() says what
  /// is wrong.
  explicit ProbeGeometry(std::vector<Vec3> positions, std::optional<std::size_t> leading = std::nullopt);

  /// Whether the probe can give a 3-D velocity, naming the tip(s) at fault:
  /// at least 4 tips, finite coordinates, no tip listed twice (two equal
  /// positions), one leading tip, and at least one combination of three
  /// trailing tips not in one plane with the leading tip whose conditioning
  /// reaches `conditioning_min`. Invalid, quantity "tips", otherwise.
  [[nodiscard]] Validation check(double conditioning_min) const;

  [[nodiscard]] std::size_t tip_count() const { return positions_.size(); }
  [[nodiscard]] const std::vector<Vec3>& positions() const { return positions_; }
  /// The leading tip's index (the most upstream one unless given; 0 when the
  /// choice is refused by check()).
  [[nodiscard]] std::size_t leading() const { return leading_; }
  /// The trailing tips' indices in increasing order: a bubble's partners are
  /// given in this order (PiercedBubbles::trailing).
  [[nodiscard]] const std::vector<std::size_t>& trailing_tips() const { return trailing_; }
  /// S_0k, |S_0k| and c_0k of the trailing tip at position `k` of trailing_tips().
  [[nodiscard]] Vec3 offset(std::size_t k) const;
  [[nodiscard]] double distance(std::size_t k) const;
  [[nodiscard]] Vec3 cosines(std::size_t k) const;
  /// Every combination of three trailing tips, in lexicographic order of
  /// their positions in trailing_tips().
  [[nodiscard]] const std::vector<TipCombination>& combinations() const { return combinations_; }
  /// "tip 2 (5.00, 1.50, 0.00) mm": how messages name a tip.
  [[nodiscard]] std::string tip_name(std::size_t tip) const;

 private:
  std::vector<Vec3> positions_;
  std::optional<std::size_t> given_leading_;
  std::size_t leading_ = 0;
  std::vector<std::size_t> trailing_;
  std::vector<TipCombination> combinations_;
};

}  // namespace awcc
