#pragma once
// A multi-tip scene validated bubble by bubble (METHOD 11.7; pdp validate
// for a probe of four or more tips, and the error study over tip geometry):
// synthesise the scene with libsynth's truth per bubble, process it, and
// score every estimate against the truth.
//
// Matching. A leading bubble is the truth row whose front interface at the
// leading tip lies within `tolerance` of the estimated front (the closest
// one). The tolerance is one sampling interval: a sampled interface lies
// within half an interval of the true one (awcc/interface_times.hpp), and two
// bubbles' fronts at one tip are at least the first one's chord time apart
// (a tip is inside one bubble at a time), so one interval finds the bubble
// and never reaches a neighbour. A partner at trailing tip k is right when
// its front lies within the tolerance of the matched row's front at tip k;
// it is wrong otherwise, also when the leading bubble has no truth row or
// its truth bubble never reached tip k (the partner is then another bubble).
//
// What is scored:
//  - pairing errors: wrong partners / partners, per trailing tip and over
//    all; the pairs found of those the truth holds (yield);
//  - per bubble (each accepted vector whose leading bubble is matched):
//    speed error ||v| - |v_true|| / |v_true| and vector error
//    |v - v_true| / |v_true|, v_true the truth's mean over the bubble's
//    interaction interval (synth/bubble_truth.hpp: what the solvers measure);
//    Shen & Nakamura's front diameter against the bubble's volume-equivalent
//    diameter |D - d| / d; median and percentiles (awcc::summarise);
//  - the mean vector against the realised fluid mean (component error over
//    the realised speed: a transverse mean is near zero, a relative error of
//    it meaningless), Tu_x, Tu_y, Tu_z against the realised ones (relative);
//  - the interfacial area concentration against 6 c / d_b
//    (Truth::expected_interfacial_area) and against the realised one at the
//    leading tip (TipTruth::interfacial_area);
//  - the dual tip (the leading tip and the first trailing tip downstream of
//    it, as pdp process chooses the pair): event detection's pairing and its
//    per-bubble velocity u_h = dx / centre lag against the bubble's v_x, and
//    the mean velocity and Tu of ED and AWCC against the realised u_x and
//    Tu_x. For a sphere in uniform motion the centre lag is S . v / |v|^2, so
//    u_h = |v|^2 / v_x: the per-bubble error of ED holds the transverse
//    velocity as well as timing and mis-pairing.
//  - pdp's own verdict on each algorithm's vectors (ProbeResult::quality and
//    quality_reason): a wrong result is only a bug of pdp when it is not
//    flagged, so a validation reports both.
// The processing is pdp process's: the synthetic signals become a
// BinarisedRecording of the declared probe (its tips' positions, the leading
// tip the most upstream one), processed by awcc::process_binarised with
// multi-tip processing and event detection on, once per velocity algorithm
// (the pairing does not depend on it, so both are scored on one pairing;
// Tian et al. 2015 gives no size or normals).

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "awcc/event_detection.hpp"
#include "awcc/multi_tip.hpp"
#include "awcc/phase_statistics.hpp"
#include "study/run.hpp"
#include "study/tasks.hpp"
#include "study/validate.hpp"
#include "synth/bubble_truth.hpp"
#include "synth/scene.hpp"

namespace study {

struct MultiTipValidateOptions {
  /// The pairing's options (the probe's joint pairing and the dual tip's
  /// event detection both read them, as in pdp process; their roc and
  /// weighting are `dual.awcc`'s, ProcessOptions::effective_event_options).
  awcc::EventOptions events;
  /// The solvers' options; run once per algorithm in `algorithms` (its own
  /// `algorithm` is overridden).
  awcc::MultiTipOptions multi_tip;
  /// Both by default: the study compares them.
  std::vector<awcc::VelocityAlgorithm> algorithms{awcc::VelocityAlgorithm::shen_nakamura,
                                                  awcc::VelocityAlgorithm::tian};
  /// FSCC and AWCC on the dual tip, as the dual-tip validation runs them.
  RunOptions dual;
  /// Matching tolerance in sampling intervals (see above): one finds the
  /// bubble and never a neighbour.
  double match_tolerance_samples = 1.0;
};

/// The truth row of each crossing at `tip`: the row whose front at that tip
/// lies within `tolerance` (s) of the crossing's front, the closest one;
/// none when no row does. O((N + R) log R).
std::vector<std::optional<std::size_t>> match_truth_rows(const synth::BubbleTruth& truth, std::size_t tip,
                                                         std::span<const awcc::Crossing> crossings, double tolerance);

/// How a pairing of the leading tip with one trailing tip scored.
struct PartnerScore {
  std::int64_t partners = 0;     ///< leading bubbles the pairing gave a partner
  std::int64_t wrong = 0;        ///< of them, not the same truth bubble
  /// Matched leading bubbles whose truth bubble pierced the trailing tip
  /// (front within the record): the partners there are to find.
  std::int64_t truth_pairs = 0;
  std::int64_t found = 0;        ///< of them, paired with the right partner
  /// wrong / partners (NaN without partners).
  [[nodiscard]] double error_fraction() const;
  /// found / truth_pairs (NaN without truth pairs).
  [[nodiscard]] double yield() const;
  PartnerScore& operator+=(const PartnerScore& other);
};

/// Scores the partners of the leading bubbles at trailing tip `tip`: `rows`
/// the leading bubbles' truth rows (match_truth_rows), `partner_fronts` the
/// front of each one's partner (none when unpaired), both in leading-bubble
/// order; `tolerance` in s.
PartnerScore score_partners(const synth::BubbleTruth& truth, std::span<const std::optional<std::size_t>> rows,
                            std::size_t tip, std::span<const std::optional<double>> partner_fronts, double tolerance);

/// An estimate against its truth. error = (value - truth) / scale: scale is
/// the truth for a relative error, the realised speed for a mean component.
struct Compared {
  std::optional<double> value;  ///< empty when the method gave none
  double truth = 0.0;
  double scale = 0.0;
  [[nodiscard]] std::optional<double> error() const;
};

/// One velocity algorithm's vectors against the truth.
struct VectorValidation {
  awcc::MultiTipResult result;  ///< what the solvers gave (status, counts, per-bubble vectors)
  awcc::Summary speed_error;    ///< per bubble, ||v| - |v_true|| / |v_true|
  awcc::Summary vector_error;   ///< per bubble, |v - v_true| / |v_true|
  awcc::Summary diameter_error; ///< per bubble, |D_front - d| / d (Shen & Nakamura; count 0 with Tian)
  std::array<Compared, 3> mean_velocity;         ///< m/s, error over the realised speed
  /// The same weighted mean of the accepted bubbles' true vectors (those
  /// matched to a truth row) against the realised mean, error over the
  /// realised speed: the part of the mean's error that is which bubbles were
  /// accepted (selection, mis-pairing's bubbles excluded), not how well each
  /// was measured.
  std::array<Compared, 3> selected_velocity;
  /// Accepted bubbles with at least one wrong partner (or no truth row), and
  /// their share of the weights of the mean vector: mis-paired lags are long,
  /// so such a bubble has a small speed and a long interaction span.
  std::int64_t accepted_mispaired = 0;
  double mispaired_weight_share = 0.0;
  std::array<Compared, 3> turbulence_intensity;  ///< relative
  Compared interfacial_area;           ///< 1/m, all bubbles' estimator, against 6 c / d_b (relative)
  Compared interfacial_area_realised;  ///< 1/m, the same against the leading tip's realised IAC (relative)
  /// 1/m, the sum over the accepted bubbles (Shen & Nakamura only), against 6 c / d_b.
  Compared interfacial_area_paired;
  /// pdp's verdict on these vectors (ProbeResult::quality): low or
  /// insufficient says a user is warned; a large error with quality ok is
  /// what the validation exists to find.
  awcc::AwccQuality quality = awcc::AwccQuality::insufficient;
  std::string quality_reason;  ///< why not ok
};

/// The dual tip: event detection and AWCC on one tip pair.
struct DualTipValidation {
  std::size_t leading_tip = 0, trailing_tip = 1;
  double dx = 0.0, dy = 0.0;    ///< streamwise and transverse separation, m
  awcc::EventResult events;     ///< event detection on the pair
  /// ED's partners against the truth: those of its pairing, before its
  /// outlier cutoff (as the probe's pairing, which has none).
  PartnerScore pairing;
  awcc::Summary velocity_error; ///< per paired bubble (after the cutoff), |u_h - v_x| / |v_x|
  Compared ed_velocity, ed_turbulence_intensity;      ///< against the realised u_x and Tu_x (relative)
  Compared awcc_velocity, awcc_turbulence_intensity;  ///< same, AWCC (value only when quality is ok or low)
  /// pdp process's processing of the probe (the first algorithm's): FSCC,
  /// AWCC and event detection of the pair, `probe` the multi-tip result.
  awcc::ProcessResult processed;
};

struct MultiTipValidation {
  synth::Scene scene;
  awcc::ProbeGeometry geometry;
  double conditioning = 0.0;            ///< the best combination's |det A_0|
  // Truth.
  std::array<double, 3> realised_velocity{};            ///< m/s
  std::array<double, 3> realised_turbulence_intensity{};
  double expected_interfacial_area = 0.0;              ///< 6 c / d_b, 1/m
  std::optional<double> realised_interfacial_area;     ///< at the leading tip, 1/m
  std::int64_t truth_bubbles = 0;       ///< rows of the truth table
  // Matching.
  std::int64_t leading_bubbles = 0;     ///< crossings at the leading tip
  std::int64_t leading_matched = 0;     ///< of them, with a truth row
  /// The probe's pairing, per trailing tip (order of trailing_tips()), and over all.
  std::vector<PartnerScore> pairing;
  PartnerScore pairing_total;
  /// The pairing's fate counts per trailing tip (ProbePairing::fates), and
  /// its status and message (refused without a first velocity).
  std::vector<std::array<std::int64_t, awcc::bubble_fate_count>> pairing_fates;
  awcc::EventStatus pairing_status = awcc::EventStatus::ok;
  std::string pairing_message;
  std::vector<VectorValidation> algorithms;  ///< in the options' order
  DualTipValidation dual;
  double seconds_synth = 0.0, seconds_process = 0.0;
};

/// Synthesises `scene` (four or more tips; throws std::invalid_argument
/// naming the tips otherwise, awcc::OptionError when the geometry is
/// refused, awcc::InputError when pdp process refuses the probe, e.g. no tip
/// downstream of the leading one) with the truth per bubble, processes it
/// and scores it.
MultiTipValidation validate_multi_tip(const synth::Scene& scene, const MultiTipValidateOptions& options = {});

/// The readable report: geometry, pairing, per-bubble errors, the statistics
/// of each algorithm against the truth, the dual tip.
std::string multi_tip_report(const MultiTipValidation& v);

/// The JSON of one run: seed; probe (tips, leading_tip, conditioning);
/// truth (realised velocity and turbulence_intensity vectors,
/// interfacial_area_expected and _realised, bubbles); pairing
/// (leading_bubbles, leading_matched, per trailing tip and over all:
/// partners, wrong, error_fraction, truth_pairs, found, yield, and each
/// tip's fates); algorithms (by name: status, reason, fates, speed_error,
/// vector_error and diameter_error as count/median/p90, mean_velocity and
/// turbulence_intensity as [x, y, z] of value/truth/error,
/// interfacial_area, interfacial_area_vs_realised and interfacial_area_paired,
/// quality and quality_reason); dual_tip (tips, dx,
/// dy, ED's status, pairing and per-bubble velocity_error, ED's and AWCC's
/// velocity and turbulence_intensity as value/truth/error); run times.
/// Errors are null where the method gave no value.
nlohmann::json multi_tip_to_json(const MultiTipValidation& v);

/// `repeat` validations of the scene: the scene's own seed for one run, else
/// run i has seed awcc::derive_seed(scene.seed, i) (as run_repeats).
std::vector<MultiTipValidation> validate_multi_tip_repeats(const synth::Scene& scene,
                                                           const MultiTipValidateOptions& options, int repeat,
                                                           const Progress& progress = {});

/// Each error's mean and 95 % interval over the runs that gave it: pairing
/// error fraction, each algorithm's median per-bubble speed error, mean
/// components (over the realised speed), Tu_x, Tu_y, Tu_z and IAC (against
/// 6 c / d_b), and ED's and AWCC's u_x and Tu_x. Relative, as fractions.
/// Each algorithm's quality is counted in the report (runs of quality ok).
std::vector<ErrorSummary> summarise_multi_tip(const std::vector<MultiTipValidation>& runs);
std::string multi_tip_repeats_report(const std::vector<MultiTipValidation>& runs,
                                     const std::vector<ErrorSummary>& summary, std::uint64_t seed);
/// repeat, error (by key: runs, mean, ci95), and runs (multi_tip_to_json each).
nlohmann::json multi_tip_repeats_to_json(const std::vector<MultiTipValidation>& runs,
                                         const std::vector<ErrorSummary>& summary);

}  // namespace study
