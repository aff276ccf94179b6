#pragma once
// The signal check (METHOD.md 2, before any statistics): is a tip's voltage a
// phase-detection signal, two levels with excursions between them, and is
// its air level where the probe type says? Noise from a disconnected probe, a
// dead or clipped channel or an inverted recording binarises into plausible
// void fractions and velocities; this check refuses them (InputError naming
// the file and the tip) unless allow-bad-signal asks to process them anyway,
// and the tip's result then carries the failure.
//
// From the voltage histogram binarisation gathered (at the data's resolution
// q: one count, or 0.1 mV for floating data), in this order:
//  0. Binary input (two distinct values, the higher air) was binarised by
//     whoever wrote it: no voltage to check, status binary_input; only the
//     polarity cue 5a applies, to its air value. One value (or two within
//     one step of the resolution) is not binary input but one level (4). A
//     dead channel flickering between exactly two counts passes as binary
//     input: nothing tells it from a 0/1 file.
//  1. Levels: the histogram threshold rule with 100 bins over the observed
//     range [min, max] (choose_threshold, bin width 0: scale-free) gives the
//     low and high modes L_lo < L_hi, their separation D = L_hi - L_lo and
//     their midpoint m, the threshold theta = 0.5 would give.
//  2. Saturated: for 16-bit recordings, whose limits are known (counts
//     -32767 and 32767, and beyond), a share of samples at a limit of
//     max_rail_share (1 %) or more is a level clipped by the digitiser: the
//     true level and the threshold between the levels are unknown. The ten
//     real recordings hold no sample there; clipping them (gain x 1.25)
//     puts 95 % of the samples at the limit, and noise larger than the range
//     74 %, which the flat-level test alone would take for two levels. Other
//     sample types do not record their limits: not tested.
//  3. No flat level: a phase-detection signal holds a level flat while the
//     tip stays in one phase. The flatness of a side is the share of its
//     samples (those below m for L_lo, from m up for L_hi) within D / 8 of
//     its level; the flatter side must reach min_flatness (0.6). Measured:
//     the real recordings' water level 0.980-0.998 (their air level, dips
//     that rarely settle, 0.22-0.84), synthetic c 0.005-0.6 at least 0.982;
//     Gaussian noise 0.02-0.15 (its two modes lie within a fraction of a
//     standard deviation), uniform noise 0.22-0.40 (at most 0.5: a side
//     R / 2 wide keeps (D / 4) / (R / 2) within D / 8), a 50 Hz sine (mains
//     hum on an open input) 0.47, with noise 0.41. A level spread evenly
//     over a band B keeps (D / 4) / B of its side within D / 8 when centred:
//     a slow drift of the levels by about 0.3 D passes (real recording 05,
//     0.8 V over 45 s: 0.65), by 0.4 D or more it fails (1.2 V: 0.49),
//     before the drift carries a level across m (about 0.5 D, where c goes
//     wrong).
//     A trough between two modes is not required: at c = 0.004 (recording
//     01) the dips rarely reach the air level, the air side has no mode and
//     no trough (trough / smaller mode 0.63).
//  4. One level (a flat level that passed 3): every sample at one value, or
//     D < min_separation_counts (16) x q (four bits between the levels: a
//     dead channel's levels are 1-2 counts apart, the real recordings'
//     11,000-22,000), or fewer than min_minor_share (0.01 %) of the samples
//     on the far side of m (the real recordings hold at least 0.36 % there,
//     synthetic c = 0.005 0.46 %).
//     A tip in clear water or air throughout looks the same: processed with
//     allow-bad-signal it gives c = 0 or 1.
//  5. Polarity. probe states which level is air (conductivity: the low one,
//     optical: the high one); c' = the share of samples on that level's side
//     of m. Two cues:
//     a. The continuous phase holds the majority of the samples and the
//        dispersed one makes the excursions: c' > 0.7 (flow_regime's droplet
//        regime) says the stated air level is the continuous phase. That is
//        a spray region, legitimately, or a bubbly recording (c = 1 - c')
//        read with inverted polarity: one signal cannot tell them apart.
//     b. The no-signal state (no current through a conductivity probe's
//        tip: air; no light returned to an optical probe: water) is the level
//        nearer 0 V. Conclusive when both levels have one sign and one is at
//        least zero_level_ratio (2) times farther from 0 V than the other
//        (the real recordings: 3.0-5.0, except 1.7 at 2 mm, synthetic 13.7).
//        For a recording of positive voltages this always agrees with probe;
//        it contradicts only a recording whose sign is inverted.
//     Both a and b: inverted_polarity, an error. a alone: air_continuous, a
//     flag (the check passes, its text goes to the warnings): a genuine spray
//     recording is never refused, an inverted bubbly one never passes
//     silently. b alone says nothing (a recording with inverting electronics
//     read with probe = optical). An inverted spray recording reads as a
//     bubbly one: no cue can tell.
// The check reads the histogram's nonempty values once (at most 65,536 for
// 16-bit data): 0.35 ms a tip on a real recording (900,000 frames), 6 % of
// its binarisation.

#include <optional>
#include <string>
#include <string_view>

#include "awcc/binarisation.hpp"
#include "awcc/validation.hpp"

namespace awcc {

struct SignalCheckOptions {
  /// Process a tip whose signal fails the check, the failure in its result
  /// and the recording's warnings (the declared option allow-bad-signal).
  bool allow_bad_signal = false;
  double max_rail_share = 0.01;          ///< 2: share of samples at a 16-bit limit that makes a level clipped, -
  double min_flatness = 0.6;             ///< 3: least share of the flatter side within D / 8 of its level, -
  double min_separation_counts = 16.0;   ///< 4: least separation of the levels, in histogram resolutions
  double min_minor_share = 1e-4;         ///< 4: least share of samples on the far side of the midpoint, -
  double zero_level_ratio = 2.0;         ///< 5b: how much farther from 0 V the signal level must lie, -
  /// Look for two tips holding one signal twice (awcc/process.hpp,
  /// copied_channel_correlation). Not a user's option: off only where the
  /// caller pairs a tip with itself on purpose (the Python module's
  /// one-tip binarise and phase statistics, which pass one array twice).
  bool find_copies = true;

  [[nodiscard]] Validation validate() const;
};

/// What the check saw on one tip.
enum class SignalStatus {
  two_level,          ///< a phase-detection signal, polarity as probe states
  binary_input,       ///< two values at most: already binarised, not checked
  unchecked,          ///< no histogram (signals handed over binarised)
  air_continuous,     ///< passes, flagged: the stated air level holds more than 70 % (spray, or inverted)
  one_level,          ///< fails: constant, nearly so, or no excursions
  no_flat_level,      ///< fails: noise, hum, or levels drifting
  saturated,          ///< fails: a level clipped at the digitiser's limit
  inverted_polarity,  ///< fails: the stated air level holds more than 70 % and lies farther from 0 V (sign inverted)
};
std::string_view to_string(SignalStatus status);

struct SignalCheck {
  SignalStatus status = SignalStatus::unchecked;
  /// What was seen and the likely cause (empty for two_level, binary_input, unchecked).
  std::string message;
  /// The check failed and the tip was processed anyway (allow-bad-signal).
  bool overridden = false;
  // The measurements (NaN where not measured, e.g. binary input):
  double low_level = 0.0, high_level = 0.0;  ///< V: L_lo, L_hi
  double flatness = 0.0;                     ///< the flatter side's share within D / 8 of its level, -
  double minor_share = 0.0;                  ///< share of samples on the minority side of the midpoint, -
  double rail_share = 0.0;                   ///< share at a 16-bit limit, -
  double air_share = 0.0;                    ///< c': share on the stated air level's side, -

  /// True when the tip must not be processed unless allowed.
  [[nodiscard]] bool failed() const;
};

/// The limits of the digitiser, V: the values of its extreme counts.
struct DigitiserLimits {
  double low = 0.0, high = 0.0;
};
/// The limits of a 16-bit recording of `quantum` volts per count (-32767 and
/// 32767 counts: -32768 too lies at or beyond the low one).
DigitiserLimits int16_limits(double quantum);

/// Checks one tip's histogram; `limits` when the digitiser's are known.
/// Never throws for a bad signal: the caller decides (failed(), allow_bad_signal).
SignalCheck check_signal(const VoltageHistogram& histogram, ProbeType probe, std::optional<DigitiserLimits> limits,
                         const SignalCheckOptions& options = {});

/// The warning a checked tip gives every output (its flag, or a failure
/// processed anyway), starting "channel K (leading tip): "; empty when none.
std::string signal_warning(const SignalCheck& check, int channel, std::string_view tip);

}  // namespace awcc
