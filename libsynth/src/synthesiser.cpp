#include "synth/synthesiser.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <deque>
#include <fmt/format.h>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <tuple>
#include <unordered_map>

#include "synth/overlap.hpp"
#include "synth/placement.hpp"
#include "synth/random.hpp"
#include "synth/velocity.hpp"

namespace synth {
namespace {

// Bubble sizes: d = d_b exp(s z), z standard normal truncated to |z| <= 3 so
// that the control volume (sized by the largest bubble) stays finite.
struct SizeModel {
  double median = 0.0;
  double log_sd = 0.0;
  double aspect = 1.0;
  double max_diameter = 0.0;
  double x_factor = 1.0;        // semi-axis along x = (d/2) x_factor
  double lateral_factor = 1.0;  // lateral semi-axes = (d/2) lateral_factor

  explicit SizeModel(const Scene& s)
      : median(s.bubble_diameter), log_sd(s.diameter_log_sd), aspect(s.aspect_ratio) {
    max_diameter = median * std::exp(3.0 * log_sd);
    // Volume kept equal to the sphere of diameter d: a_x a_y a_z = (d/2)^3.
    x_factor = std::cbrt(aspect * aspect);
    lateral_factor = 1.0 / std::cbrt(aspect);
  }

  double draw(Rng& rng) const {
    if (log_sd == 0.0) return median;
    double z;
    do z = rng.normal(); while (std::fabs(z) > 3.0);
    return median * std::exp(log_sd * z);
  }

  // Surface of the bubble of diameter 1 (an ellipsoid of revolution about x
  // with the volume of the unit-diameter sphere): S scales as d^2.
  double unit_surface() const {
    const double polar = 0.5 * x_factor, equatorial = 0.5 * lateral_factor;
    if (polar == equatorial) return std::numbers::pi;
    if (polar < equatorial) {  // oblate
      const double e = std::sqrt(1.0 - polar * polar / (equatorial * equatorial));
      return 2.0 * std::numbers::pi * equatorial * equatorial +
             std::numbers::pi * polar * polar / e * std::log((1.0 + e) / (1.0 - e));
    }
    const double e = std::sqrt(1.0 - equatorial * equatorial / (polar * polar));  // prolate
    return 2.0 * std::numbers::pi * equatorial * equatorial * (1.0 + polar / (equatorial * e) * std::asin(e));
  }

  // E[d^k] of the truncated log-normal, by Simpson's rule on z in [-3, 3].
  double moment(double k) const {
    if (log_sd == 0.0) return std::pow(median, k);
    const int n = 600;
    const double h = 6.0 / n;
    double num = 0.0, den = 0.0;
    for (int i = 0; i <= n; ++i) {
      const double z = -3.0 + h * i;
      const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
      const double pdf = std::exp(-0.5 * z * z);
      num += w * pdf * std::pow(median * std::exp(log_sd * z), k);
      den += w * pdf;
    }
    return num / den;
  }
};

// Minimum-image separation on a periodic interval of the given length.
// Separations are rarely more than one period off (bubbles live for a few
// milliseconds), so one conditional shift beats a call to nearbyint on this
// hot path. Both shift conditions are read off the input (after a shift
// down the value cannot be below -half, so this is what testing the shifted
// value gave), which keeps them off each other's latency; a separation
// within one length needs no more (the shift lands in [-half, half]).
inline double wrap(double separation, double length) {
  const double half = 0.5 * length;
  const double above = length * static_cast<double>(separation > half);
  const double below = length * static_cast<double>(separation < -half);
  const bool far = std::fabs(separation) > length;
  separation = (separation - above) + below;
  if (far && (separation > half || separation < -half)) [[unlikely]] {
    separation -= length * std::nearbyint(separation / length);
  }
  return separation;
}

// The complement over [0, samples) of sorted, disjoint, non-touching
// intervals inside it: the gaps between them, which are as well.
std::vector<awcc::AirInterval> complement(const std::vector<awcc::AirInterval>& intervals, std::int64_t samples) {
  std::vector<awcc::AirInterval> out;
  out.reserve(intervals.size() + 1);
  std::int64_t from = 0;
  for (const auto& i : intervals) {
    if (i.start > from) out.push_back({from, i.start});
    from = i.stop;
  }
  if (from < samples) out.push_back({from, samples});
  return out;
}

// What the pierce walk reads of every step (key, t_entry, entry_step,
// clear_until) comes first, on one cache line.
struct ActiveBubble {
  Vec3 key;        // D(t_entry)
  double t_entry;
  std::int64_t entry_step = 0;  // the velocity step in which it entered
  // Per tip (the first few): the probe's lateral path length below which
  // the tip cannot reach this bubble (Synthesiser::pierce_tip).
  static constexpr std::size_t cached_tips = 4;
  std::array<double, cached_tips> clear_until{};
  Vec3 entry;      // relative to the probe centre
  Vec3 inv_axes;   // 1 / semi-axes
  double a_x;      // semi-axis along x
  double radius;   // d/2, for overlap tests in the sphere-mapped space
  double clear_reach;  // (1 + lateral_margin) a_lat (Synthesiser::clear_until)
  std::uint64_t serial;
  std::uint64_t pierced_mask = 0;
};

// Active bubbles sorted by key.x: a vector with a moving head, so that the
// neighbour searches of the placement run on contiguous memory (a
// std::deque's iterators made them the hot spot). Appends dominate;
// retirement advances the head.
class BubbleQueue {
 public:
  using iterator = std::vector<ActiveBubble>::iterator;
  iterator begin() { return items_.begin() + static_cast<std::ptrdiff_t>(head_); }
  iterator end() { return items_.end(); }
  [[nodiscard]] bool empty() const { return head_ == items_.size(); }
  ActiveBubble& front() { return items_[head_]; }
  void pop_front() {
    if (++head_ >= 4096 && 2 * head_ >= items_.size()) {
      items_.erase(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(head_));
      erased_ += head_;
      head_ = 0;
    }
  }
  /// The first bubble whose key.x is not below `key` (std::partition_point's
  /// answer), found by walking from where the last search with this `hint`
  /// ended: keys move a little from one step to the next, so the walk is a
  /// step or two where a binary search is a dozen unpredictable branches.
  iterator first_not_below(double key, std::size_t& hint) { return first_after<false>(key, hint); }
  /// The first bubble whose key.x is above `key`, found so.
  iterator first_above(double key, std::size_t& hint) { return first_after<true>(key, hint); }
  /// A new bubble at the end, to be filled in, then settle_last().
  ActiveBubble& append() { return items_.emplace_back(); }
  /// Moves the last bubble back to its place in key order (it is there
  /// already unless the flow reversed while it entered).
  void settle_last() {
    const auto last = items_.end() - 1;
    auto pos = last;
    while (pos != begin() && std::prev(pos)->key.x > last->key.x) --pos;
    if (pos != last) std::rotate(pos, last, items_.end());
  }

 private:
  // The first bubble whose key.x is not below `key` (above it, if strict).
  template <bool strict>
  iterator first_after(double key, std::size_t& hint) {
    auto before = [key](double k) { return strict ? k <= key : k < key; };
    std::size_t i = hint >= erased_ ? std::clamp(hint - erased_, head_, items_.size()) : head_;
    while (i > head_ && !before(items_[i - 1].key.x)) --i;
    // Mostly one bubble or none: that one without a branch, so that the
    // loop's test is nearly always false (a walk of 0 or 1 was a
    // mispredicted branch a step).
    if (i < items_.size()) i += static_cast<std::size_t>(before(items_[i].key.x));
    while (i < items_.size() && before(items_[i].key.x)) ++i;
    hint = i + erased_;
    return items_.begin() + static_cast<std::ptrdiff_t>(i);
  }

  std::vector<ActiveBubble> items_;
  std::size_t head_ = 0;
  std::size_t erased_ = 0;  // items erased from the front so far: hints survive the compaction
};

// A neighbour of a bubble being placed, as every placement attempt tests it.
// Its lateral disc is the placement's (same index).
struct Neighbour {
  double sx2, r2;  // squared streamwise separation and squared sum of radii (sphere-mapped)
};

struct Pending {
  double diameter;
  double first_key;  // D_x when it first tried to enter
  double next_try;   // D_x at which to try again
};

// A tip crossing a bubble's surface, as the truth per bubble states it.
struct Interface {
  double t = 0.0;
  Vec3 displacement;  // D(t)
  Vec3 velocity;      // u(t)
  Vec3 normal;        // outward unit normal of the surface at the tip
};

// One tip's pierce of the bubble being walked, while the tip is inside.
struct OpenPierce {
  bool inside = false;
  double t_in = 0.0;
  std::int64_t step = 0;  // the step in which it opened
  Interface front;        // with bubble_truth
};

// One velocity step as the pierce walk reads it: the common displacement
// and the lateral path length at its start and end, its velocity, and the
// steps with u_x < 0 up to it.
struct Step {
  Vec3 d;
  Vec3 u;
  double path, path_next;
  std::int64_t backward;  // steps up to and including this one with u_x < 0
};

// The keys of the bubbles a step can bring within a_x_max of a tip
// streamwise (Synthesiser::walk).
struct Reach {
  double lo, hi;
  /// Whether a step of these keys can bring a bubble of this key within reach.
  [[nodiscard]] bool holds(double key) const { return lo <= key && key <= hi; }
};

// Steps [from, to) at which a bubble of key `key` was not yet within reach
// of a tip: so neither is any bubble of a larger key (Synthesiser::walk).
struct NotThere {
  double key = -std::numeric_limits<double>::infinity();
  std::int64_t from = 0, to = 0;
};

// What a step's view hands to the pierce test: the step and its start time.
struct StepView {
  const Step& h;
  double t;
};

// A term of a tip's interfacial-area sum (bubble_truth), kept with its
// place in time: the step of the pierce's end, then the bubbles' key order;
// the pierces still open at the record's end last, in the order they
// opened. Summed in that order at the end, so that the sum does not depend
// on the order in which bubbles are walked.
struct AreaTerm {
  bool at_end;
  std::int64_t step;
  double key;
  std::uint64_t serial;
  double front, rear;  // 0 when the interface is not in the record
  bool operator<(const AreaTerm& o) const {
    return std::tie(at_end, step, key, serial) < std::tie(o.at_end, o.step, o.key, o.serial);
  }
};

// A pierced bubble's truth while it is still active.
struct BubbleInProgress {
  std::vector<TipPierce> tips;
  Interface first, last;  // earliest and latest interface at any tip
  std::int32_t extra_passes = 0;
};

// Streaming velocity statistics for the truth.
class FlowAccumulator {
 public:
  FlowAccumulator(const Scene& scene, double dt) : dt_(dt) {
    mean_ = {scene.velocity, 0.0, 0.0};
    const double t_min = std::min({scene.time_scale_of(0), scene.time_scale_of(1), scene.time_scale_of(2)});
    const double t_max = std::max({scene.time_scale_of(0), scene.time_scale_of(1), scene.time_scale_of(2)});
    decimation_ = std::max<std::int64_t>(1, static_cast<std::int64_t>(std::floor(t_min / (20.0 * dt))));
    const double lags = std::ceil(10.0 * t_max / (static_cast<double>(decimation_) * dt));
    lags_ = static_cast<std::size_t>(std::clamp(lags, 16.0, 4000.0));
    for (auto& r : ring_) r.assign(lags_ + 1, 0.0);
    for (auto& p : lagged_) p.assign(lags_ + 1, 0.0);
  }

  // Scalars, not an array: stored as a pair and a single and read back
  // across the two, an array stalled each step on a failed store forward.
  void add(const Vec3& u) {
    const double yx = u.x - mean_[0], yy = u.y - mean_[1], yz = u.z - mean_[2];
    sum_[0] += yx;
    sum_[1] += yy;
    sum_[2] += yz;
    cross_[0][0] += yx * yx;
    cross_[0][1] += yx * yy;
    cross_[0][2] += yx * yz;
    cross_[1][1] += yy * yy;
    cross_[1][2] += yy * yz;
    cross_[2][2] += yz * yz;
    // Every decimation_-th step from the first, by a countdown (an integer
    // division a step was a tenth of the step loop).
    if (--until_decimated_ == 0) {
      until_decimated_ = decimation_;
      decimate(yx, yy, yz);
    }
    ++count_;
  }

  RealisedFlow finish() const {
    RealisedFlow out;
    out.steps = count_;
    if (count_ == 0) return out;
    const double n = static_cast<double>(count_);
    double m[3], var[3];
    for (int i = 0; i < 3; ++i) {
      m[i] = sum_[i] / n;
      out.mean_velocity[i] = mean_[i] + m[i];
      var[i] = std::max(0.0, cross_[i][i] / n - m[i] * m[i]);
      out.rms_velocity[i] = std::sqrt(var[i]);
    }
    const double speed = std::hypot(out.mean_velocity[0], out.mean_velocity[1], out.mean_velocity[2]);
    for (int i = 0; i < 3; ++i) out.turbulence_intensity[i] = speed > 0.0 ? out.rms_velocity[i] / speed : 0.0;
    auto rho = [&](int i, int j) -> std::optional<double> {
      const double denom = std::sqrt(var[i] * var[j]);
      if (!(denom > 0.0)) return std::nullopt;
      return (cross_[i][j] / n - m[i] * m[j]) / denom;
    };
    out.rho_xy = rho(0, 1);
    out.rho_xz = rho(0, 2);
    out.rho_yz = rho(1, 2);
    for (int i = 0; i < 3; ++i) out.integral_time_scale[i] = integral_scale(i);
    return out;
  }

 private:
  std::optional<double> integral_scale(int i) const {
    const auto nd = static_cast<std::size_t>(decimated_);
    if (nd < 4) return std::nullopt;
    const double mean = dsum_[i] / static_cast<double>(nd);
    auto cov = [&](std::size_t k) {
      return lagged_[i][k] / static_cast<double>(nd - k) - mean * mean;
    };
    const double c0 = cov(0);
    if (!(c0 > 1e-300)) return std::nullopt;
    const std::size_t max_lag = std::min(lags_, nd - 2);
    const double h = static_cast<double>(decimation_) * dt_;
    double integral = 0.0;
    double previous = 1.0;
    for (std::size_t k = 1; k <= max_lag; ++k) {
      const double r = cov(k) / c0;
      if (r <= 0.0) {
        // Up to the zero crossing, by linear interpolation.
        const double frac = previous / (previous - r);
        integral += 0.5 * previous * frac * h;
        return integral;
      }
      integral += 0.5 * (previous + r) * h;
      previous = r;
    }
    return integral;
  }

  [[gnu::noinline]] void decimate(double yx, double yy, double yz) {
    const double y[3] = {yx, yy, yz};
    const std::size_t slot = decimated_ % (lags_ + 1);
    const std::size_t available = std::min<std::size_t>(decimated_, lags_);
    for (int i = 0; i < 3; ++i) {
      auto& ring = ring_[i];
      auto& lagged = lagged_[i];
      ring[slot] = y[i];
      // ring[slot - k] for k <= slot, then wrapped around the end.
      const std::size_t direct = std::min(available, slot);
      for (std::size_t k = 0; k <= direct; ++k) lagged[k] += y[i] * ring[slot - k];
      for (std::size_t k = direct + 1; k <= available; ++k) lagged[k] += y[i] * ring[slot + lags_ + 1 - k];
      dsum_[i] += y[i];
    }
    ++decimated_;
  }

  double dt_;
  std::array<double, 3> mean_{};
  std::int64_t count_ = 0;
  double sum_[3] = {0, 0, 0};
  double cross_[3][3] = {};
  std::int64_t decimation_ = 1;
  std::int64_t until_decimated_ = 1;  // steps to the next decimated one, this one included
  std::size_t lags_ = 16;
  std::size_t decimated_ = 0;
  double dsum_[3] = {0, 0, 0};
  std::array<std::vector<double>, 3> ring_;
  std::array<std::vector<double>, 3> lagged_;
};

class Synthesiser {
 public:
  Synthesiser(const Scene& scene, const SynthesisOptions& options)
      : scene_(scene), options_(options), sizes_(scene), bubble_rng_(scene.seed, Stream::bubbles) {
    dt_ = scene.effective_realisation_step();
    fs_ = scene.fs;
    duration_ = scene.duration;
    samples_ = scene.sample_count();

    const auto tips = scene.probe_tips();
    Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (const auto& t : tips) {
      lo = {std::min(lo.x, t.x), std::min(lo.y, t.y), std::min(lo.z, t.z)};
      hi = {std::max(hi.x, t.x), std::max(hi.y, t.y), std::max(hi.z, t.z)};
    }
    const Vec3 centre{0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z)};
    for (const auto& t : tips) tips_.push_back({t.x - centre.x, t.y - centre.y, t.z - centre.z});
    tip_x_min_ = lo.x - centre.x;
    tip_x_max_ = hi.x - centre.x;

    a_x_max_ = 0.5 * sizes_.max_diameter * sizes_.x_factor;
    const double a_lat_max = 0.5 * sizes_.max_diameter * sizes_.lateral_factor;
    length_[0] = (hi.x - lo.x) + 4.0 * a_x_max_;
    length_[1] = (hi.y - lo.y) + 4.0 * a_lat_max;
    length_[2] = (hi.z - lo.z) + 4.0 * a_lat_max;
    entry_x_ = -0.5 * length_[0];
    placement_ = LateralPlacement(length_[1], length_[2]);

    // Bubbles, or droplets in the spray region: the particles are placed at
    // their own volume fraction, c or 1 - c (synth::DispersedPhase).
    const double mean_volume = std::numbers::pi / 6.0 * sizes_.moment(3.0);
    const double area = length_[1] * length_[2];
    rate_ = fraction_ * scene.velocity * area / mean_volume;
    // Tip pierce rate: flux of particle cross-sections pi a_y a_z through the tip.
    const double mean_section = std::numbers::pi * 0.25 * sizes_.lateral_factor * sizes_.lateral_factor *
                                sizes_.moment(2.0);
    expected_pierce_rate_ = fraction_ * scene.velocity * mean_section / mean_volume;
    spacing_ = scene.velocity / rate_;  // metres of flow between entries (space rules)
    reversal_allowance_ = std::max(2.0 * length_[0], 4.0 * scene.velocity * scene.tu * scene.time_scale_of(0));

    // Pre-roll: enough flow before t = 0 for the control volume to be in its
    // stationary state when the record starts.
    pre_steps_ = static_cast<std::int64_t>(std::ceil(2.0 * length_[0] / scene.velocity / dt_)) + 1;
    t_start_ = -static_cast<double>(pre_steps_) * dt_;
    record_steps_ = static_cast<std::int64_t>(std::ceil(duration_ / dt_));

    pierces_.resize(tips_.size());
    {
      // Room for the pierces expected (the equal-time rate, more by about
      // 1 + Tu^2 for the fast flow's extra particles) and 5 % more, so that
      // the arrays are not grown by doubling: each doubling leaves the old
      // array behind as a hole in the heap that a sweep's next run keeps
      // (awcc::keep_freed_memory). At most one pierce every two samples.
      const double expected = expected_pierce_rate_ * duration_ * (1.0 + scene.tu * scene.tu) * 1.05 + 256.0;
      const auto room = static_cast<std::size_t>(std::min(expected, 0.5 * static_cast<double>(samples_) + 1.0));
      for (auto& p : pierces_) p.reserve(room);
    }
    pair_counts_.assign(tips_.size() * tips_.size(), 0);
    not_there_.resize(tips_.size());
    reach_.resize(tips_.size());
    block_reach_.resize(tips_.size());
    tip_counts_.assign(tips_.size(), 0);
    if (options.bubble_truth) {
      table_.tip_count = tips_.size();
      area_terms_.resize(tips_.size());
    }

    const bool time_rule = scene.arrival == ArrivalRule::equal_time || scene.arrival == ArrivalRule::poisson_time;
    const bool poisson = scene.arrival == ArrivalRule::poisson_time || scene.arrival == ArrivalRule::poisson_space;
    // First arrival: a uniform phase (equal spacing) or an exponential gap.
    const double first = poisson ? bubble_rng_.exponential() : bubble_rng_.uniform();
    if (time_rule) {
      next_time_ = t_start_ + first / rate_;
    } else {
      next_key_ = first * spacing_;
    }
    time_rule_ = time_rule;
    allow_overlap_ = scene_.overlap == OverlapRule::allow;
    poisson_ = poisson;
  }

  Synthesis run() {
    Synthesis out;
    VelocityProcess velocity(scene_, dt_);
    FlowAccumulator flow(scene_, dt_);
    std::optional<VelocityHistory> history;
    if (options_.keep_velocity_history) history.emplace(dt_);
    if (options_.keep_reference_data) {
      out.reference.emplace();
      out.reference->t_start = t_start_;
      out.reference->step = dt_;
      out.reference->tips = tips_;
      out.reference->control_volume = {length_[0], length_[1], length_[2]};
    }

    const std::int64_t total = pre_steps_ + record_steps_;
    const std::int64_t chunk = std::max<std::int64_t>(1, options_.chunk_steps);
    std::vector<Vec3> buffer(static_cast<std::size_t>(std::min(chunk, total)));
    for (std::int64_t first = 0; first < total; first += chunk) {
      const std::int64_t n = std::min(chunk, total - first);
      std::span<Vec3> block(buffer.data(), static_cast<std::size_t>(n));
      velocity.generate(block);
      for (std::int64_t i = 0; i < n; ++i) {
        const std::int64_t step = first + i;
        const Vec3& u = block[static_cast<std::size_t>(i)];
        const double t = t_start_ + static_cast<double>(step) * dt_;
        if (options_.keep_reference_data) out.reference->velocities.push_back(u);
        if (step == pre_steps_) record_start_x_ = d_.x;
        step_ = step;
        advance(t, u);
        if (step >= pre_steps_) {
          flow.add(u);
          if (history) history->push_back(history->back() + u.x * dt_);
        }
      }
      if (options_.progress) options_.progress(static_cast<double>(first + n) / static_cast<double>(total));
    }
    // The bubbles still in the control volume: walked to the last step,
    // a pierce still open ending with the record.
    for (auto& b : bubbles_) walk(b, total - 1, true);
    for (const auto& b : bubbles_) tally(b);
    if (options_.keep_reference_data) out.reference->bubbles = std::move(records_);

    // Signals and truth.
    Truth& truth = out.truth;
    truth.imposed = scene_;
    truth.realisation_step = dt_;
    for (int i = 0; i < 3; ++i) truth.control_volume[i] = length_[i];
    truth.bubble_rate = rate_;
    truth.expected_pierce_rate = expected_pierce_rate_;
    truth.dispersed_phase = phase_;
    truth.expected_interfacial_area =
        fraction_ * sizes_.unit_surface() * sizes_.moment(2.0) / (std::numbers::pi / 6.0 * sizes_.moment(3.0));
    truth.realised = flow.finish();
    truth.bubbles_generated = generated_;
    truth.overlaps_unresolved = overlaps_unresolved_;
    truth.compensated_volume_fraction =
        compensated_volume_ > 0.0 ? compensated_volume_ / (length_[1] * length_[2] * (d_.x - record_start_x_)) : 0.0;
    truth.reentries_missed = reentries_missed_;
    truth.sample_count = samples_;
    const auto given_tips = scene_.probe_tips();
    for (std::size_t j = 0; j < tips_.size(); ++j) {
      awcc::AirIntervals signal;
      signal.fs = fs_;
      signal.sample_count = samples_;
      signal.intervals = std::move(pierces_[j]);
      awcc::normalise(signal.intervals);
      // The pierces are the particles': for droplets air is everything else.
      if (phase_ == DispersedPhase::droplets) signal.intervals = complement(signal.intervals, samples_);
      TipTruth tip;
      tip.position = given_tips[j];
      tip.void_fraction = signal.void_fraction();
      tip.chords = static_cast<std::int64_t>(signal.intervals.size());
      tip.bubbles_pierced = tip_counts_[j];
      if (options_.bubble_truth) tip.interfacial_area = area_sum(j) / duration_;
      truth.tips.push_back(tip);
      out.signals.push_back(std::move(signal));
      for (std::size_t k = j + 1; k < tips_.size(); ++k) {
        truth.pairs.push_back({static_cast<int>(j), static_cast<int>(k), pair_counts_[j * tips_.size() + k]});
      }
    }
    out.history = std::move(history);
    if (options_.bubble_truth) out.bubbles = finish_table();
    return out;
  }

 private:
  // One velocity step [t, t + dt) at constant velocity u.
  void advance(double t, const Vec3& u) {
    const Vec3 d_next{d_.x + u.x * dt_, d_.y + u.y * dt_, d_.z + u.z * dt_};
    lateral_path_next_ = lateral_path_ + std::sqrt(u.y * u.y + u.z * u.z) * dt_;
    // Most steps have no event: what arrivals' loop finds first, checked
    // here, without the call.
    if (!pending_.empty() || (time_rule_ ? next_time_ - t < dt_ : next_key_ <= d_next.x)) arrivals(t, u, d_next);
    backward_ += static_cast<std::int64_t>(u.x < 0.0);
    history_.push_back({d_, u, lateral_path_, lateral_path_next_, backward_});
    path_next_.push_back(lateral_path_next_);
    // The keys of the bubbles this step can bring within a_x_max of tip j
    // streamwise: the bubble's x relative to the tip is entry_x + D_x - key - P_jx.
    const double d_lo = std::min(d_.x, d_next.x), d_hi = std::max(d_.x, d_next.x);
    const bool new_block = (step_ & (block_steps - 1)) == 0;
    for (std::size_t j = 0; j < tips_.size(); ++j) {
      const Reach r{entry_x_ + d_lo - tips_[j].x - a_x_max_, entry_x_ + d_hi - tips_[j].x + a_x_max_};
      reach_[j].push_back(r);
      if (new_block) block_reach_[j].push_back(r);
      Reach& block = block_reach_[j].back();
      block = {std::min(block.lo, r.lo), std::max(block.hi, r.hi)};
    }
    // A bubble retired may have come back to a tip: counted, not pierced.
    if (entry_x_ + d_lo - tip_x_max_ - a_x_max_ < max_retired_key_) ++reentries_missed_;
    retire(d_next);
    d_ = d_next;
    lateral_path_ = lateral_path_next_;
  }

  // Arrivals and retries of waiting bubbles during the step, in time order.
  void arrivals(double t, const Vec3& u, const Vec3& d_next) {
    auto at = [&](double s) { return Vec3{d_.x + u.x * s, d_.y + u.y * s, d_.z + u.z * s}; };
    double cursor = 0.0;  // offset into the step of the last event
    for (;;) {
      double s_arrival;
      if (time_rule_) {
        s_arrival = next_time_ - t;
      } else {
        // A bubble enters each time the displacement first passes the next mark.
        s_arrival = next_key_ <= d_next.x ? std::clamp((next_key_ - d_.x) / u.x, 0.0, dt_) : dt_;
      }
      double s_retry = dt_;
      if (!pending_.empty()) {
        const double target = pending_.front().next_try;
        if (target <= d_.x) s_retry = cursor;
        else if (u.x > 0.0 && target <= d_next.x) s_retry = (target - d_.x) / u.x;
      }
      s_retry = std::max(s_retry, cursor);
      if (s_arrival >= dt_ && s_retry >= dt_) break;
      if (s_retry < s_arrival) {
        cursor = s_retry;
        place_pending(t + s_retry, at(s_retry));
        continue;
      }
      cursor = std::max(cursor, s_arrival);
      Vec3 key = at(s_arrival);
      if (!time_rule_) key.x = next_key_;
      pending_.push_back({sizes_.draw(bubble_rng_), key.x, key.x});
      place_pending(t + s_arrival, key);
      if (time_rule_) {
        next_time_ += (poisson_ ? bubble_rng_.exponential() : 1.0) / rate_;
      } else {
        next_key_ += (poisson_ ? bubble_rng_.exponential() : 1.0) * spacing_;
      }
      if (!time_rule_) bring_forward(key.x);
    }
  }

  // Places waiting bubbles in arrival order. Bubbles never move relative to
  // each other, so an overlap at entry is an overlap for ever. When every
  // lateral position tried overlaps a neighbour, the bubble waits and tries
  // again at each later arrival (the ones behind it wait in the queue) and
  // each time the flow has advanced by a quarter of the largest diameter,
  // until it has advanced by one largest diameter; then it is placed
  // overlapping (Truth::overlaps_unresolved). In a dense flow that is about
  // two tries a bubble (c 0.42, log-normal sizes at sd 0.6: 4.67 M tries,
  // 2.49 M of them failed, for 2.18 M bubbles). Waiting keeps the bubble
  // flux (a bubble is late, never lost) and lets the void fraction reach c
  // above the jamming limit of random sequential placement (about 0.38 for
  // spheres), where placing overlapping bubbles at once would lose the
  // overlapped volume.
  void place_pending(double t_entry, const Vec3& key) {
    while (!pending_.empty()) {
      Pending& p = pending_.front();
      const bool must_place = allow_overlap_ || key.x - p.first_key >= 2.0 * a_x_max_;
      if (!try_place(p.diameter, t_entry, key, must_place)) {
        p.next_try = std::max(p.next_try, key.x) + 0.5 * a_x_max_;
        return;
      }
      pending_.pop_front();
    }
  }

  bool try_place(double diameter, double t_entry, const Vec3& key, bool must_place) {
    const double radius = 0.5 * diameter;

    // Test the neighbours in the sphere-mapped space (x scaled by 1/x_factor,
    // lateral by 1/lateral_factor) where every bubble is a sphere of radius
    // d/2. The cross-section is periodic for this test (minimum image): with
    // hard lateral walls the retries would push bubbles towards the walls,
    // away from the tips, and the tips would see a void fraction well below c
    // (0.19 instead of 0.25 in the base case).
    if (allow_overlap_) {
      // Other simulators' rule: one uniform entry point, kept.
      placement_.clear();
      neighbours_.clear();
      const auto drawn = placement_.place(bubble_rng_, 1);
      return settle(radius, t_entry, key, drawn.attempts - 1);
    }
    // Only the neighbours that can overlap the particle streamwise count. One
    // whose key is farther than its largest possible reach, radius x_factor
    // + a_x_max (with a margin for rounding), has r^2 - sx^2 < 0; so has one
    // within it that is still too far for its own size. Such a disc covers
    // no point: it never makes an attempt's margin negative, so leaving it
    // out changes no outcome and no draw (the same bits), and the attempts
    // are tested against far fewer discs where sizes are spread (log-normal
    // at sd 0.6: the window was 2 a_x_max, six median diameters, and most
    // of the discs in it covered nothing).
    const double reach = (radius * sizes_.x_factor + a_x_max_) * (1.0 + 1e-9);
    const auto lo = bubbles_.first_not_below(key.x - reach, place_hint_lo_);
    // partition_point(o.key.x <= key.x + reach): the first key above it.
    const auto hi = bubbles_.first_above(key.x + reach, place_hint_hi_);
    // What the attempts share, once: each neighbour's disc in the entry
    // plane (synth/placement.hpp).
    auto& near = neighbours_;
    near.clear();
    placement_.clear();
    const double lateral2 = sizes_.lateral_factor * sizes_.lateral_factor;
    for (auto it = lo; it != hi; ++it) {
      // Separation now: (E_b - E_o) - (key_b - key_o), with E_x equal.
      const double sx = (it->key.x - key.x) / sizes_.x_factor;
      const double r = radius + it->radius;
      if (!(r * r - sx * sx > 0.0)) continue;  // covers no point, lenses nothing (shared_volume)
      near.push_back({sx * sx, r * r});
      placement_.add_disc(it->entry.y + key.y - it->key.y, it->entry.z + key.z - it->key.z,
                          (r * r - sx * sx) * lateral2);
    }
    const auto outcome = placement_.place(bubble_rng_, scene_.overlap_retries + 1);
    if (!outcome.placed && !must_place) return false;
    int chosen = outcome.attempts - 1;  // the free one, or the last tried
    if (!outcome.placed) {
      ++overlaps_unresolved_;
      chosen = place_overlapping(radius, t_entry, key, outcome.attempts);
    }
    return settle(radius, t_entry, key, chosen);
  }

  // Keeps a particle at the placement's position `chosen`.
  bool settle(double radius, double t_entry, const Vec3& key, int chosen) {
    // Built where it is kept: a copy of a bubble just written field by field
    // stalled on the store forwards.
    ActiveBubble& b = bubbles_.append();
    b.key = key;
    b.t_entry = t_entry;
    b.entry_step = step_;
    b.entry = {entry_x_, placement_.y(chosen), placement_.z(chosen)};
    b.radius = radius;
    b.a_x = radius * sizes_.x_factor;
    const double a_lat = radius * sizes_.lateral_factor;
    b.inv_axes = {1.0 / b.a_x, 1.0 / a_lat, 1.0 / a_lat};
    b.clear_reach = (1.0 + lateral_margin) * a_lat;
    // The lateral skip from the entry on (pierce_tip): at entry the bubble
    // sits at lateral offset entry - P_j from tip j (D = key), and the
    // path since the step's start, not counted here, only makes the
    // threshold lower than it could be. Most bubbles pass every tip at a
    // distance and are never looked at again.
    for (std::size_t j = 0; j < std::min(tips_.size(), ActiveBubble::cached_tips); ++j) {
      b.clear_until[j] = clear_until(b, lateral_path_, b.entry.y - tips_[j].y, b.entry.z - tips_[j].z);
    }
    b.serial = serial_++;
    if (t_entry >= 0.0 && t_entry < duration_) ++generated_;
    if (options_.keep_reference_data) {
      records_.push_back({t_entry, b.entry, b.key, {b.a_x, 1.0 / b.inv_axes.y, 1.0 / b.inv_axes.z}});
    }
    bubbles_.settle_last();
    return true;
  }

  // The volume a particle of the given radius shares, entered at lateral
  // (y, z), with the neighbours of try_place's list, in the sphere-mapped
  // space (volume-preserving): the sum of the pairwise lenses. A point also
  // inside a second neighbour is counted twice, but two neighbours can share
  // volume only when one of them was itself placed overlapping
  // (docs/validation.md measures the excess).
  [[nodiscard]] double shared_volume(double radius, double y, double z) const {
    const double lateral2 = sizes_.lateral_factor * sizes_.lateral_factor;
    double volume = 0.0;
    for (std::size_t k = 0; k < neighbours_.size(); ++k) {
      const Neighbour& o = neighbours_[k];
      const double separation2 = o.sx2 + placement_.distance2(k, y, z) / lateral2;
      if (separation2 >= o.r2) continue;
      volume += lens_volume(radius, std::sqrt(o.r2) - radius, std::sqrt(separation2));
    }
    // A particle cannot lose more than its own volume. Summed over a pile of
    // overlapping neighbours the lenses can exceed it, and owing that excess
    // brought the next mark back to the current displacement for ever (a
    // hang at c = 0.35 with one position tried, issue 33).
    return std::min(volume, (4.0 / 3.0) * std::numbers::pi * radius * radius * radius);
  }

  // Every lateral position tried (the placement's first `tried`) overlaps:
  // the one the particle takes. Under the space rules it goes where it
  // shares the least volume, and that volume is owed to the flow
  // (bring_forward); under the time rules it stays at the last position
  // tried and the volume is lost (synthesiser.hpp, "Dense placement").
  int place_overlapping(double radius, double t_entry, const Vec3& key, int tried) {
    if (time_rule_) return tried - 1;
    double least = std::numeric_limits<double>::infinity();
    int best = tried - 1;
    for (int i = 0; i < tried; ++i) {
      const double v = shared_volume(radius, placement_.y(i), placement_.z(i));
      if (v < least) {
        least = v;
        best = i;
      }
    }
    if (t_entry >= 0.0 && t_entry < duration_) compensated_volume_ += least;
    debt_volume_ += least;
    bring_forward(key.x);
    return best;
  }

  // Brings the next mark forward by the flow that carries the owed volume
  // at the dispersed fraction, lost / (c_d A), but not behind `now` (the
  // current event's displacement): what is left is owed on, to the marks
  // after it.
  void bring_forward(double now) {
    if (!(debt_volume_ > 0.0)) return;
    const double per_volume = 1.0 / (fraction_ * length_[1] * length_[2]);  // m of flow per m^3 owed
    const double owed = debt_volume_ * per_volume;
    const double room = std::max(0.0, next_key_ - now);
    if (owed <= room) {
      next_key_ -= owed;
      debt_volume_ = 0.0;
    } else {
      next_key_ -= room;
      debt_volume_ -= room / per_volume;
    }
  }

  // The pierces of bubble b, walked step by step from its entry to step
  // `last` over the velocity steps kept in history_ (retire() walks a bubble
  // when it leaves, run() the ones left at the end, with at_end). The steps
  // tested are those whose range of keys holds it (at most a_x_max from the
  // tip streamwise), less the ones the lateral skip proves empty; every
  // test is pierce_tip's exact arithmetic on that step, so the air
  // intervals do not depend on how the steps are found. Past the tip with
  // no backward step to come, the walk stops: the displacement only grows
  // from there.
  void walk(ActiveBubble& b, std::int64_t last, bool at_end) {
    const double key = b.key.x;
    const std::int64_t first = history_first_;
    const Step* steps = history_.data();  // steps[s - first] is step s, as in every array below
    const double* path_next = path_next_.data();
    const std::int64_t backward_to_last = steps[last - first].backward;
    for (std::size_t j = 0; j < tips_.size(); ++j) {
      const Reach* reach = reach_[j].data();
      // Not there yet: the steps before the first whose keys reach it.
      // Bubbles are walked in key order, so the last bubble's steps not
      // there yet are this one's too (NotThere).
      NotThere& hint = not_there_[j];
      std::int64_t s = b.entry_step;
      if (key >= hint.key && s >= hint.from) s = std::max(s, hint.to);
      s = first_of(s, last, [&](std::int64_t i) { return key <= reach[i - first].hi; });
      hint = {key, b.entry_step, s};
      const bool cached = j < ActiveBubble::cached_tips;
      OpenPierce open;
      std::int64_t end = last + 1;  // the steps [s, end) hold the candidates
      if (s <= last && steps[s - first].u.x >= 0.0 && steps[s - first].backward == backward_to_last) {
        // Forward from s to the last step: the keys reached only grow, so
        // the candidates are the steps up to the first that has passed it.
        end = first_of(s, last, [&](std::int64_t i) { return key < reach[i - first].lo; });
        // pierce_tip's lateral skip over all of them at once: a bubble
        // further from the tip at the first than a_lat and the lateral path
        // to the end of the last cannot hold it at any (most pass at a
        // distance, and are then never tested step by step).
        if (cached && s < end) {
          const Step& h = steps[s - first];
          const double d2 = nearest_image2(wrap(b.entry.y + h.d.y - b.key.y, length_[1]) - tips_[j].y,
                                           wrap(b.entry.z + h.d.z - b.key.z, length_[2]) - tips_[j].z);
          const double need = path_next[end - 1 - first] - h.path + b.clear_reach;
          if (need * need < d2) s = end;
        }
      }
      const Reach* block = block_reach_[j].data();  // block[(s >> block_shift) - first_block]: s's block
      const std::int64_t first_block = first >> block_shift;
      for (; s < end; ++s) {
        const Reach& r = reach[s - first];
        if (key < r.lo || key > r.hi) {
          if (key < r.lo && steps[s - first].backward == backward_to_last) break;  // past the tip for good
          // The flow reversed somewhere ahead: on to the next step that can
          // bring it within reach, whole blocks at a time.
          while (((s + 1) & (block_steps - 1)) == 0 && s + 1 < end &&
                 !block[((s + 1) >> block_shift) - first_block].holds(key)) {
            s += block_steps;
          }
          continue;
        }
        // The lateral skip (pierce_tip), before the call.
        if (cached && !open.inside && path_next[s - first] < b.clear_until[j]) continue;
        const double t = t_start_ + static_cast<double>(s) * dt_;
        pierce_tip(b, j, {steps[s - first], t}, std::max(0.0, b.t_entry - t), open, s);
      }
      if (at_end && open.inside) emit(j, b, open.t_in, duration_, {true, open.step}, bubble_truth_ ? &open.front : nullptr);
    }
  }

  // The first step i in [from, last] with found(i), else last + 1: four
  // steps tested at a time without a branch, so that the loop's exit (most
  // walks find it within the first four) is the only branch taken on data.
  template <class Found>
  static std::int64_t first_of(std::int64_t from, std::int64_t last, Found found) {
    for (std::int64_t i = from; i <= last; i += 4) {
      unsigned hits = 0;
      for (std::int64_t k = 0; k < 4; ++k) {
        hits |= static_cast<unsigned>(found(std::min(i + k, last)) && i + k <= last) << k;
      }
      if (hits) return i + std::countr_zero(hits);
    }
    return last + 1;
  }

  // Whether the tip stays outside the bubble for the whole step by one
  // coordinate alone: |q + v s| >= |q| - |v| dt > 1 for s in [0, dt]. The
  // margin (1e-9 of the unit form) is far above the rounding of the roots
  // below, so a skipped bubble is one whose roots lie outside the step
  // whichever way they are rounded: skipping changes no output.
  [[nodiscard]] bool outside_all_step(double q, double v) const {
    return std::fabs(q) - std::fabs(v) * dt_ > 1.0 + 1e-9;
  }

  // Most candidates pass the tip at a lateral distance: the bubble moves
  // with the flow, the tip with it laterally by at most the lateral path
  // length of the probe (the minimum-image distance is 1-Lipschitz). A
  // bubble found at lateral distance D at the start of a step cannot hold
  // the tip until that path has grown by D - a_lat; until then it is
  // skipped. The margin (1e-3 a_lat) is orders of magnitude above the
  // rounding of the path sum and of the positions over a bubble's passage,
  // so a skipped bubble is one that the full test would pass over too:
  // skipping changes no output.
  static constexpr double lateral_margin = 1e-3;

  // The lateral path length below which the tip cannot reach b, from the
  // tip's offset (lateral_y, lateral_z) at the step's start: the distance
  // to the tip's nearest periodic image (lateral_y is one image of the
  // offset, as the bubble's image is chosen before the tip's offset is
  // taken; the other is length - |lateral_y|) less a_lat and the margin.
  // Lateral semi-axes are equal (try_place).
  [[nodiscard]] double clear_until(const ActiveBubble& b, double path, double lateral_y, double lateral_z) const {
    return path + std::sqrt(nearest_image2(lateral_y, lateral_z)) - b.clear_reach;
  }
  [[nodiscard]] double nearest_image2(double lateral_y, double lateral_z) const {
    const double ny = std::min(std::fabs(lateral_y), length_[1] - std::fabs(lateral_y));
    const double nz = std::min(std::fabs(lateral_z), length_[2] - std::fabs(lateral_z));
    return ny * ny + nz * nz;
  }

  // One step of tip j's walk over bubble b (walk): the step starting at
  // view.t, the bubble there from s0 into it; `open` is the tip's pierce of
  // this bubble, open while the tip is inside.
  void pierce_tip(ActiveBubble& b, std::size_t j, const StepView& view, double s0, OpenPierce& open, std::int64_t step) {
    const Vec3& p = tips_[j];
    const Step& h = view.h;
    const double t = view.t;
    const Vec3& u = h.u;
    const bool was_inside = open.inside;
    const bool cached = j < ActiveBubble::cached_tips;
    const double lateral_y = wrap(b.entry.y + h.d.y - b.key.y, length_[1]) - p.y;
    const double lateral_z = wrap(b.entry.z + h.d.z - b.key.z, length_[2]) - p.z;
    if (cached && !was_inside) {
      // The skip below, before the roots: a bubble further from the tip
      // than a_lat and the step's lateral path cannot hold it during the
      // step, whatever its streamwise position (most candidates pass at a
      // distance: this spares them the quadratic). Decided on squares,
      // L_next - L + reach < D as (L_next - L + reach)^2 < D^2 (both sides
      // positive), so that the branch does not wait for the square root,
      // which only the threshold kept for later steps needs.
      const double d2 = nearest_image2(lateral_y, lateral_z);
      const double need = h.path_next - h.path + b.clear_reach;
      b.clear_until[j] = h.path + std::sqrt(d2) - b.clear_reach;
      if (need * need < d2) return;
    }
    const double qx = (b.entry.x + h.d.x - b.key.x - p.x) * b.inv_axes.x;
    const double vx = u.x * b.inv_axes.x;
    const double qy = lateral_y * b.inv_axes.y;
    const double vy = u.y * b.inv_axes.y;
    const double qz = lateral_z * b.inv_axes.z;
    const double vz = u.z * b.inv_axes.z;
    const double a = vx * vx + vy * vy + vz * vz;
    const double bh = qx * vx + qy * vy + qz * vz;
    const double c = qx * qx + qy * qy + qz * qz - 1.0;

    // Inside at the step's start (the pierce is open) and at its end: an
    // ellipsoid is convex, so inside all step, and no roots are needed
    // (most steps of a pierce; the roots below decide the rest as before).
    if (was_inside && c + dt_ * (2.0 * bh + a * dt_) < 0.0) return;

    // Roots of a s^2 + 2 bh s + c = 0: the tip is inside for s in (r1, r2).
    double r1 = 0.0, r2 = 0.0;
    bool crosses = false;
    if (a > 0.0) {
      const double disc = bh * bh - a * c;
      if (disc > 0.0) {
        const double sq = std::sqrt(disc);
        const double qq = -(bh + std::copysign(sq, bh));
        r1 = qq / a;
        r2 = qq != 0.0 ? c / qq : -r1;
        if (r1 > r2) std::swap(r1, r2);
        crosses = true;
      }
    } else if (c < 0.0) {
      r1 = -std::numeric_limits<double>::infinity();
      r2 = std::numeric_limits<double>::infinity();
      crosses = true;
    }

    if (was_inside) {
      if (crosses && r2 > s0 && r2 >= dt_) return;  // still inside at the step's end
      const double s_out = !crosses || r2 <= s0 ? s0 : r2;
      if (bubble_truth_) {
        const Interface rear = interface_at(b, j, view, s_out);
        emit(j, b, open.t_in, t + s_out, {false, step}, &open.front, &rear);
      } else {
        emit(j, b, open.t_in, t + s_out, {false, step});
      }
      open.inside = false;
      return;
    }
    if (!crosses || r2 <= s0 || r1 >= dt_) {
      if (cached) b.clear_until[j] = clear_until(b, h.path, lateral_y, lateral_z);
      return;
    }
    const double s_in = std::max(r1, s0);
    const double t_in = t + s_in;
    Interface front;
    if (bubble_truth_) front = interface_at(b, j, view, s_in);
    if (r2 < dt_) {
      if (bubble_truth_) {
        const Interface rear = interface_at(b, j, view, r2);
        emit(j, b, t_in, t + r2, {false, step}, &front, &rear);
      } else {
        emit(j, b, t_in, t + r2, {false, step});
      }
    } else {
      open.inside = true;
      open.t_in = t_in;
      open.step = step;
      open.front = front;
    }
  }

  // The tip's crossing of the bubble's surface s into the step starting at
  // t: the surface point is the tip, relative to the centre r = P_j - x_k,
  // and the outward normal of |r / a|^2 = 1 there is along r / a^2.
  // Out of line, as record_pierce: the truth's code kept off pierce_tip's
  // hot path leaves its inlining as it was (4 % faster with the table off).
  [[nodiscard]] [[gnu::noinline]] Interface interface_at(const ActiveBubble& b, std::size_t j, const StepView& view,
                                                        double s) const {
    const Vec3& p = tips_[j];
    const Vec3& d = view.h.d;
    const Vec3& u = view.h.u;
    const Vec3 r{p.x - (b.entry.x + d.x - b.key.x + u.x * s),
                 p.y - (wrap(b.entry.y + d.y - b.key.y, length_[1]) + u.y * s),
                 p.z - (wrap(b.entry.z + d.z - b.key.z, length_[2]) + u.z * s)};
    const Vec3 g{r.x * b.inv_axes.x * b.inv_axes.x, r.y * b.inv_axes.y * b.inv_axes.y,
                 r.z * b.inv_axes.z * b.inv_axes.z};
    const double norm = std::sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    Interface out;
    out.t = view.t + s;
    out.displacement = {d.x + u.x * s, d.y + u.y * s, d.z + u.z * s};
    out.velocity = u;
    out.normal = {g.x / norm, g.y / norm, g.z / norm};
    return out;
  }

  // Where an emitted pierce's area terms go in the sum (AreaTerm): ended in
  // `step`, or still open at the record's end, opened in `step`.
  struct EmitOrder {
    bool at_end;
    std::int64_t step;
  };

  // front, rear: the interfaces with bubble_truth (rear null when the record
  // ends with the tip inside).
  void emit(std::size_t j, ActiveBubble& b, double t_in, double t_out, EmitOrder order,
            const Interface* front = nullptr, const Interface* rear = nullptr) {
    if (t_out <= 0.0 || t_in >= duration_) return;
    // A rear interface after the record's end is not in it: the pierce is
    // censored there, as when the record ends with the tip inside.
    if (front) record_pierce(j, b, order, *front, rear && rear->t < duration_ ? rear : nullptr);
    b.pierced_mask |= std::uint64_t{1} << j;
    // Samples strictly inside (t_in, t_out).
    const auto start = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor(t_in * fs_)) + 1);
    const auto stop = std::min<std::int64_t>(samples_, static_cast<std::int64_t>(std::ceil(t_out * fs_)));
    if (start < stop) pierces_[j].push_back({start, stop});
  }

  void retire(const Vec3& d_next) {
    const double limit = entry_x_ + std::min(d_.x, d_next.x) - tip_x_max_ - a_x_max_ - reversal_allowance_;
    while (!bubbles_.empty() && bubbles_.front().key.x < limit) {
      ActiveBubble& b = bubbles_.front();
      walk(b, step_, false);
      max_retired_key_ = std::max(max_retired_key_, b.key.x);
      tally(b);
      bubbles_.pop_front();
    }
    forget_history();
  }

  // Drops the steps before the earliest entry of a bubble still active:
  // no walk reads them again.
  void forget_history() {
    // Seldom, so that the steps kept (a bubble's life, about 2,000 in the
    // base case) are moved seldom.
    if (step_ < next_forget_) return;
    next_forget_ = step_ + 16384;
    std::int64_t earliest = step_;
    for (auto it = bubbles_.begin(); it != bubbles_.end(); ++it) earliest = std::min(earliest, it->entry_step);
    earliest &= ~(block_steps - 1);  // whole blocks
    const std::int64_t drop = earliest - history_first_;
    if (2 * drop < static_cast<std::int64_t>(history_.size())) return;
    history_.erase(history_.begin(), history_.begin() + static_cast<std::ptrdiff_t>(drop));
    path_next_.erase(path_next_.begin(), path_next_.begin() + static_cast<std::ptrdiff_t>(drop));
    for (auto& r : reach_) r.erase(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(drop));
    for (auto& r : block_reach_) r.erase(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(drop >> block_shift));
    history_first_ = earliest;
  }

  // Tip j's sum of 1 / |u . n| over its interfaces, added in AreaTerm's order.
  [[nodiscard]] double area_sum(std::size_t j) {
    auto& terms = area_terms_[j];
    std::sort(terms.begin(), terms.end());
    double sum = 0.0;
    for (const auto& a : terms) {
      sum += a.front;
      sum += a.rear;
    }
    return sum;
  }

  void tally(const ActiveBubble& b) {
    if (b.pierced_mask == 0) return;
    if (bubble_truth_) finish_row(b);
    const std::size_t n = tips_.size();
    for (std::size_t j = 0; j < n; ++j) {
      if (!(b.pierced_mask >> j & 1u)) continue;
      ++tip_counts_[j];
      for (std::size_t k = j + 1; k < n; ++k) {
        if (b.pierced_mask >> k & 1u) ++pair_counts_[j * n + k];
      }
    }
  }

  // One piercing of tip j by bubble b that overlaps the record.
  [[gnu::noinline]] void record_pierce(std::size_t j, const ActiveBubble& b, EmitOrder order, const Interface& front,
                                       const Interface* rear) {
    auto [slot, added] = in_progress_.try_emplace(b.serial);
    BubbleInProgress& p = slot->second;
    if (added) {
      p.tips.assign(tips_.size(), TipPierce{});
      p.first = front;
      p.last = front;
    }
    auto consider = [&p](const Interface& i) {
      if (i.t < p.first.t) p.first = i;
      if (i.t > p.last.t) p.last = i;
    };
    consider(front);
    if (rear) consider(*rear);
    // The area concentration counts the interfaces crossing the tip in [0, T).
    auto area = [](const Interface& i) {
      const double un = i.velocity.x * i.normal.x + i.velocity.y * i.normal.y + i.velocity.z * i.normal.z;
      return 1.0 / std::fabs(un);
    };
    area_terms_[j].push_back({order.at_end, order.step, b.key.x, b.serial, front.t >= 0.0 ? area(front) : 0.0,
                              rear && rear->t < duration_ ? area(*rear) : 0.0});

    TipPierce& tip = p.tips[j];
    if (tip.pierced()) {
      ++p.extra_passes;
      return;
    }
    auto to_float = [](const Vec3& v) {
      return std::array<float, 3>{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
    };
    tip.front = front.t;
    tip.front_normal = to_float(front.normal);
    if (rear) {
      tip.rear = rear->t;
      tip.rear_normal = to_float(rear->normal);
      // Pierce points relative to the centre move by -(D(rear) - D(front)).
      const Vec3 d{rear->displacement.x - front.displacement.x, rear->displacement.y - front.displacement.y,
                   rear->displacement.z - front.displacement.z};
      tip.chord = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    }
  }

  // Moves a retiring pierced bubble's truth into the table.
  [[gnu::noinline]] void finish_row(const ActiveBubble& b) {
    const auto found = in_progress_.find(b.serial);
    if (found == in_progress_.end()) return;
    const BubbleInProgress& p = found->second;
    const double span = p.last.t - p.first.t;
    Vec3 velocity = p.first.velocity;
    if (span > 0.0) {
      velocity = {(p.last.displacement.x - p.first.displacement.x) / span,
                  (p.last.displacement.y - p.first.displacement.y) / span,
                  (p.last.displacement.z - p.first.displacement.z) / span};
    }
    table_.id.push_back(b.serial);
    table_.diameter.push_back(2.0 * b.radius);
    const double lateral = b.radius * sizes_.lateral_factor;  // as try_place sizes it, not 1 / (1 / a)
    table_.semi_axes.push_back({b.a_x, lateral, lateral});
    table_.velocity.push_back(velocity);
    table_.interaction_start.push_back(p.first.t);
    table_.interaction_end.push_back(p.last.t);
    table_.extra_passes.push_back(p.extra_passes);
    table_.pierces.insert(table_.pierces.end(), p.tips.begin(), p.tips.end());
    in_progress_.erase(found);
  }

  // The table in id order. Bubbles retire in the order of their entry
  // displacement, which is their id order unless the flow reversed while
  // they entered: then the rows are permuted, column by column.
  BubbleTruth finish_table() {
    BubbleTruth& t = table_;
    if (std::is_sorted(t.id.begin(), t.id.end())) return std::move(t);
    std::vector<std::size_t> order(t.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&t](std::size_t a, std::size_t b) { return t.id[a] < t.id[b]; });
    auto permute = [&order](auto& column) {
      auto copy = column;
      for (std::size_t i = 0; i < order.size(); ++i) column[i] = copy[order[i]];
    };
    permute(t.id);
    permute(t.diameter);
    permute(t.semi_axes);
    permute(t.velocity);
    permute(t.interaction_start);
    permute(t.interaction_end);
    permute(t.extra_passes);
    std::vector<TipPierce> pierces(t.pierces.size());
    const std::size_t n = t.tip_count;
    for (std::size_t i = 0; i < order.size(); ++i) {
      std::copy_n(t.pierces.begin() + static_cast<std::ptrdiff_t>(order[i] * n), n,
                  pierces.begin() + static_cast<std::ptrdiff_t>(i * n));
    }
    t.pierces = std::move(pierces);
    return std::move(t);
  }

  const Scene& scene_;
  const SynthesisOptions& options_;
  DispersedPhase phase_ = dispersed_phase(scene_.void_fraction);
  double fraction_ = dispersed_fraction(scene_.void_fraction);
  bool bubble_truth_ = options_.bubble_truth;
  SizeModel sizes_;
  Rng bubble_rng_;
  double dt_ = 0.0, fs_ = 0.0, duration_ = 0.0;
  std::int64_t samples_ = 0;
  std::vector<Vec3> tips_;
  double tip_x_min_ = 0.0, tip_x_max_ = 0.0;
  double a_x_max_ = 0.0;
  double length_[3] = {0, 0, 0};
  double entry_x_ = 0.0;
  double rate_ = 0.0, expected_pierce_rate_ = 0.0, spacing_ = 0.0;
  double reversal_allowance_ = 0.0;
  std::int64_t pre_steps_ = 0, record_steps_ = 0;
  double t_start_ = 0.0;
  bool time_rule_ = true, poisson_ = false;
  bool allow_overlap_ = false;  // OverlapRule::allow
  double next_time_ = 0.0, next_key_ = 0.0;

  Vec3 d_{};  // common displacement at the current step start
  // Lateral path length of the flow past the probe, sum of |u_lat| dt, at
  // the current step's start and end (pierce_tip's lateral skip).
  double lateral_path_ = 0.0, lateral_path_next_ = 0.0;
  BubbleQueue bubbles_;
  std::vector<Neighbour> neighbours_;  // scratch of try_place
  LateralPlacement placement_{0.0, 0.0};  // scratch of try_place: its discs and the positions tried
  // Dispersed volume shared by particles placed overlapping (space rules):
  // what bring_forward has yet to give back, and all of the record's.
  double debt_volume_ = 0.0, compensated_volume_ = 0.0;
  double record_start_x_ = 0.0;        // D_x(0)
  std::deque<Pending> pending_;
  std::vector<BubbleRecord> records_;
  std::uint64_t serial_ = 0;
  double max_retired_key_ = -std::numeric_limits<double>::infinity();
  // The velocity steps from the earliest entry of an active bubble on
  // (walk), history_[i] being step history_first_ + i.
  std::vector<Step> history_;
  std::vector<double> path_next_;        // history_[i].path_next, alone
  std::vector<std::vector<Reach>> reach_;  // per tip
  // Per tip and block of block_steps steps: the least lo and greatest hi of
  // its steps, so that a walk passes over blocks that cannot reach a key.
  static constexpr int block_shift = 6;
  static constexpr std::int64_t block_steps = std::int64_t{1} << block_shift;
  std::vector<std::vector<Reach>> block_reach_;
  std::int64_t history_first_ = 0, next_forget_ = 0;
  std::int64_t step_ = 0;      // the step being taken
  std::vector<NotThere> not_there_;  // per tip (walk)
  std::int64_t backward_ = 0;  // steps so far with u_x < 0
  std::size_t place_hint_lo_ = 0, place_hint_hi_ = 0;
  std::vector<std::vector<awcc::AirInterval>> pierces_;
  std::vector<std::int64_t> pair_counts_;
  std::vector<std::int64_t> tip_counts_;
  std::int64_t generated_ = 0, overlaps_unresolved_ = 0, reentries_missed_ = 0;
  // With bubble_truth: pierced bubbles still active (by serial), the rows of
  // those retired, and each tip's terms of 1 / |u . n| over its interfaces.
  std::unordered_map<std::uint64_t, BubbleInProgress> in_progress_;
  BubbleTruth table_;
  std::vector<std::vector<AreaTerm>> area_terms_;
};

template <class PerSample>
void for_each_sample_min_form(const Scene& scene, const ReferenceData& ref, PerSample&& per_sample) {
  // Bubbles sorted by key.x for a candidate range per sample (as wide as any
  // bubble can be), then a plain point-in-ellipsoid test at t = n / fs.
  std::vector<BubbleRecord> bubbles = ref.bubbles;
  std::sort(bubbles.begin(), bubbles.end(), [](const auto& a, const auto& b) { return a.key.x < b.key.x; });
  double a_max = 0.0;
  double entry_x = 0.0;
  for (const auto& b : bubbles) {
    a_max = std::max(a_max, b.semi_axes.x);
    entry_x = b.entry.x;
  }
  double tip_lo = 1e300, tip_hi = -1e300;
  for (const auto& p : ref.tips) {
    tip_lo = std::min(tip_lo, p.x);
    tip_hi = std::max(tip_hi, p.x);
  }
  // Displacement at every step start.
  std::vector<Vec3> d(ref.velocities.size() + 1);
  for (std::size_t k = 0; k < ref.velocities.size(); ++k) {
    const Vec3& u = ref.velocities[k];
    d[k + 1] = {d[k].x + u.x * ref.step, d[k].y + u.y * ref.step, d[k].z + u.z * ref.step};
  }
  const std::int64_t n_samples = scene.sample_count();
  const double fs = scene.fs;
  for (std::int64_t n = 0; n < n_samples; ++n) {
    const double t = static_cast<double>(n) / fs;
    auto k = static_cast<std::size_t>(std::floor((t - ref.t_start) / ref.step));
    k = std::min(k, ref.velocities.size() - 1);
    const double s = t - (ref.t_start + static_cast<double>(k) * ref.step);
    const Vec3& u = ref.velocities[k];
    const Vec3 dt{d[k].x + u.x * s, d[k].y + u.y * s, d[k].z + u.z * s};
    const double lo = entry_x + dt.x - tip_hi - a_max;
    const double hi = entry_x + dt.x - tip_lo + a_max;
    auto it = std::partition_point(bubbles.begin(), bubbles.end(), [&](const auto& b) { return b.key.x < lo; });
    for (std::size_t j = 0; j < ref.tips.size(); ++j) {
      double best = std::numeric_limits<double>::infinity();
      for (auto b = it; b != bubbles.end() && b->key.x <= hi; ++b) {
        if (!(t > b->t_entry)) continue;
        const double x = (b->entry.x + dt.x - b->key.x - ref.tips[j].x) / b->semi_axes.x;
        const double y = (wrap(b->entry.y + dt.y - b->key.y, ref.control_volume.y) - ref.tips[j].y) / b->semi_axes.y;
        const double z = (wrap(b->entry.z + dt.z - b->key.z, ref.control_volume.z) - ref.tips[j].z) / b->semi_axes.z;
        best = std::min(best, x * x + y * y + z * z);
      }
      per_sample(j, n, best);
    }
  }
}

}  // namespace

Synthesis synthesise(const Scene& scene, const SynthesisOptions& options) {
  if (const auto validation = scene.validate(); !validation.ok()) throw invalid_scene(validation);
  Synthesiser synthesiser(scene, options);
  return synthesiser.run();
}

std::span<const awcc::OptionField<SynthesisOptions>> synthesis_option_fields() {
  static const awcc::OptionField<SynthesisOptions> fields[] = {
      {"bubble-truth", "",
       "also give the truth per pierced bubble (a table <name>.truth.bubbles.csv beside a recording's sidecar) "
       "and the true interfacial area concentration at each tip; 84 bytes plus 48 a tip per pierced bubble",
       [](SynthesisOptions& o, std::string_view t) {
         if (t == "on" || t == "true") o.bubble_truth = true;
         else if (t == "off" || t == "false") o.bubble_truth = false;
         else throw std::invalid_argument(fmt::format("'{}' is not on or off", t));
       },
       [](const SynthesisOptions& o) { return std::string(o.bubble_truth ? "on" : "off"); }, true},
  };
  return fields;
}

std::vector<std::vector<std::uint8_t>> brute_force_signals(const Scene& scene, const ReferenceData& reference) {
  std::vector<std::vector<std::uint8_t>> out(reference.tips.size(),
                                             std::vector<std::uint8_t>(static_cast<std::size_t>(scene.sample_count())));
  // Inside a particle is air for a bubble, water for a droplet.
  const bool droplets = dispersed_phase(scene.void_fraction) == DispersedPhase::droplets;
  for_each_sample_min_form(scene, reference, [&](std::size_t j, std::int64_t n, double form) {
    const bool inside = form < 1.0;
    out[j][static_cast<std::size_t>(n)] = inside != droplets ? 1 : 0;
  });
  return out;
}

std::vector<std::vector<double>> brute_force_distances(const Scene& scene, const ReferenceData& reference) {
  std::vector<std::vector<double>> out(reference.tips.size(),
                                       std::vector<double>(static_cast<std::size_t>(scene.sample_count())));
  const bool droplets = dispersed_phase(scene.void_fraction) == DispersedPhase::droplets;
  for_each_sample_min_form(scene, reference, [&](std::size_t j, std::int64_t n, double form) {
    out[j][static_cast<std::size_t>(n)] = droplets ? 2.0 - form : form;
  });
  return out;
}

}  // namespace synth
