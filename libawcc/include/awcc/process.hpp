#pragma once
// Processing one recording end to end: read (block by block), binarise the
// leading and trailing tips, phase statistics per tip, FSCC and AWCC (both by
// default, as the pdp command line). Results are value types with a readable
// report; their JSON and CSV forms are in awcc/serialise.hpp.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "awcc/awcc.hpp"
#include "awcc/binarisation.hpp"
#include "awcc/event_detection.hpp"
#include "awcc/fft.hpp"
#include "awcc/flags.hpp"
#include "awcc/fscc.hpp"
#include "awcc/multi_tip.hpp"
#include "awcc/phase_statistics.hpp"
#include "awcc/position_sizes.hpp"
#include "awcc/probe_tips.hpp"
#include "awcc/recording.hpp"
#include "awcc/signal_check.hpp"
#include "awcc/structure.hpp"
#include "awcc/velocity_series.hpp"

namespace awcc {

/// Whether a recording is processed bubble by bubble as a multi-tip probe
/// (METHOD 11.3-11.6).
enum class MultiTipChoice {
  automatic,  ///< for a probe of four or more tips (declared, or stated by the recording)
  off,        ///< never: the tip pair alone
  on,         ///< always: a probe of fewer than four tips is refused
};

struct ProcessOptions {
  ReaderOptions reader;
  int leading_channel = 0;            ///< channel index of the leading tip
  int trailing_channel = 1;           ///< channel index of the trailing tip
  /// Channels of a probe's further trailing tips (tips 2, 3, ... in the
  /// order their positions are declared); empty for a dual-tip probe. They
  /// are binarised with the trailing tip's options and checked like it.
  std::vector<int> further_channels;
  BinarisationOptions binarisation;
  /// Each tip's voltage must be a two-level signal of the stated polarity
  /// (awcc/signal_check.hpp) before any statistics.
  SignalCheckOptions signal_check;
  double dx = 0.0;                    ///< streamwise tip separation, m (required for velocities)
  double dy = 0.0;                    ///< lateral tip separation, m (reported)
  /// The probe's tips as declared (tips, leading-tip, tip-channels): one
  /// declaration instead of dx, dy and the two channels, which follow from
  /// it per recording (tip_pair_options()).
  ProbeTips probe;
  bool fscc = true;                   ///< run FSCC
  FsccOptions fscc_options;
  bool awcc = true;                   ///< run AWCC
  /// AWCC settings; signal = raw makes FSCC and AWCC correlate the voltages
  /// (one more pass over the file for each).
  AwccOptions awcc_options;
  /// Event detection on the tip pair (METHOD 11.1-11.2): a velocity per
  /// bubble. Off by default: its Kramer pairing is biased where bubbles are
  /// sparse (awcc/event_detection.hpp), so it runs beside FSCC and AWCC,
  /// against which every output checks it (awcc/assess.hpp).
  bool events = false;
  /// Its pairing and quality; its `roc` and `weighting` are taken from
  /// awcc_options when processing (one switch for both methods).
  EventOptions event_options;
  /// The probe bubble by bubble: 3-D velocity, sizes, interfacial area, with
  /// FSCC and AWCC on every tip pair alongside.
  MultiTipChoice multi_tip = MultiTipChoice::automatic;
  MultiTipOptions multi_tip_options;
  int histogram_bins = 50;            ///< chord-time histogram bins
  /// Chord and voltage PDFs, clusters, inter-particle arrivals (and Felder's conventions).
  StructureOptions structure;
  /// The number distribution of bubble (droplet) diameters inverted from
  /// the leading tip's chord lengths (awcc/position_sizes.hpp). On: a lab
  /// expects it, and it costs little against the rest (docs/performance.md:
  /// the repeated lengths of one velocity are inverted once each).
  bool sizes = true;
  SizesOptions size_options;
  /// The AWCC velocity series' spectrum and integral time scale (METHOD 10).
  bool velocity_spectrum = true;
  SpectrumOptions spectrum;
  /// Accept values outside the plausible ranges of the instrument (below):
  /// off, because a value out of them is nearly always a unit slip.
  bool allow_unusual = false;
  /// Frames read at a time: large enough that handing blocks between the
  /// reading and the binarising thread costs little, small enough to stay in cache.
  std::int64_t block_frames = 1 << 18;
  bool single_pass = true;            ///< allow the one-pass path for 16-bit data (same result, faster)
  /// Read the next block on a second thread while one is binarised, where a
  /// second core exists (same result; decoding FLAC or copying from the page
  /// cache then overlaps with the work on the samples).
  bool read_ahead = true;
  /// Sum FSCC's auto-correlation on a second thread while its
  /// cross-correlation is summed (awcc::fscc's second_thread), where a
  /// second core exists: the same result, bit for bit. Off in study runs,
  /// whose rows fill the cores already (study::processing_options).
  bool parallel_fscc = true;
  /// Hash the recording's file (SHA-256, ProcessResult::input_sha256) for
  /// the provenance, on the bytes as they are read where the reader allows
  /// (Recording::hash_while_reading). Off unless an output records it: the
  /// hash is not free (about 2 GB/s of one core).
  bool hash_input = false;

  /// The tips' channels: leading, trailing, then further_channels.
  [[nodiscard]] std::vector<int> tip_channels() const;
  /// event_options with AWCC's roc and weighting: what event detection runs with.
  [[nodiscard]] EventOptions effective_event_options() const;
  /// Every part's validate(), then implausible() unless allow_unusual.
  [[nodiscard]] Validation validate() const;
  /// Ok when every stated value is plausible for a phase-detection probe:
  /// dx 0.1-100 mm (or 0: no velocity), fs 1 kHz-100 MHz, a velocity range
  /// within 0.01-200 m/s; else status implausible, quantity allow-unusual,
  /// and the value, its range and the likely slip.
  [[nodiscard]] Validation implausible() const;
};

/// The options of the dual-tip processing of a recording: where tips are
/// declared (options.probe) or the recording states them
/// (RecordingInfo::tip_positions), the tip pair is the leading tip and the
/// first tip after it, in the order of the tips, that lies downstream of it
/// (positive x separation); dx is their streamwise separation, dy their
/// distance across the flow (hypot of the y and z separations), and the
/// channels theirs. A declared probe of two tips processes exactly as dx and
/// dy of the same separation. With only dx (and dy) given, a recording
/// stating its tips must agree on the pair's separation (a zero dx or dy
/// takes the file's). Processed as a multi-tip probe (multi_tip on, or
/// automatic with four or more tips), the other tips' channels become
/// further_channels in the order of the tips. The result has no declared
/// tips (it is its own tip_pair_options()). Throws InputError naming the
/// file, the tips and the fix (probe_of(), no tip downstream of the leading
/// one, a dx that disagrees with the file's, multi-tip asked of a probe of
/// fewer than four tips).
[[nodiscard]] ProcessOptions tip_pair_options(const ProcessOptions& options, const RecordingInfo& info);

/// The plausible sampling rates of a probe recording, Hz (a file's own rate is checked too).
inline constexpr double plausible_fs_min = 1e3, plausible_fs_max = 100e6;

/// Which method's velocity the chord lengths and d32 use.
enum class VelocitySource { none, awcc, fscc };
std::string_view to_string(VelocitySource source);

struct TipResult {
  int channel = 0;
  std::string name;                   ///< the channel's name in a column file's header (else empty)
  Threshold threshold;
  PhaseStatistics phase;
  SignalCheck signal;                 ///< the signal check of its voltage
};

/// Pearson's r of two tips' binary signals at lag 0 above which they are one
/// signal twice (a channel copied in the acquisition, or cross-talk), not
/// two tips. Two tips a whole sample or more apart differ at each bubble's
/// front and rear, so 1 - r is about twice the lag over the mean chord in
/// samples: 0.05 for a lag of one sample and chords of 20 (1 mm bubbles at
/// 1 m/s and 20 kHz), and 0.999 needs chords of some 2,000 samples per
/// sample of lag, where AWCC and FSCC cannot resolve the delay anyway. The
/// exact copy (the same air intervals) is refused unless a bad signal is
/// allowed; a near copy is flagged (channels_copied).
inline constexpr double copied_channel_correlation = 0.999;

/// Two tips whose binary signals are one signal twice (copied_channel_correlation).
struct ChannelCopy {
  int first = 0, second = 0;   ///< their channels
  std::string first_tip, second_tip;  ///< "leading tip", "trailing tip", "tip 3"
  double correlation = 0.0;    ///< Pearson's r of the binary signals at lag 0
  bool identical = false;      ///< the same air intervals
};

/// A further tip of a probe of more than two tips, binarised like the trailing tip.
struct BinarisedTip {
  int channel = 0;
  Threshold threshold;
  AirIntervals signal;
  std::optional<VoltageHistogram> histogram;  ///< the histogram its threshold came from
  SignalCheck check;                          ///< the signal check of its histogram
};

/// The two binary signals of a recording (what AWCC and FSCC consume), and
/// those of a probe's further tips when asked (ProcessOptions::further_channels).
struct BinarisedRecording {
  RecordingInfo info;
  Threshold leading_threshold, trailing_threshold;
  AirIntervals leading, trailing;
  /// The voltage histograms the thresholds came from (the voltage PDFs).
  std::optional<VoltageHistogram> leading_histogram, trailing_histogram;
  /// The signal check of each tip's histogram (unchecked without one).
  SignalCheck leading_signal, trailing_signal;
  std::vector<BinarisedTip> further_tips;   ///< tips 2, 3, ... in the order of further_channels
  /// Pairs of tips that hold one signal twice (processed only when a bad
  /// signal is allowed, or when nearly but not exactly the same).
  std::vector<ChannelCopy> copies;
  /// Every binarised tip's position, m, in the same order (leading,
  /// trailing, further tips), where the probe's tips are declared or stated
  /// by the recording; else empty.
  std::vector<Vec3> tip_positions;
  /// Every tip's interfaces timed at the threshold crossing, same order
  /// (threshold_crossings, EventOptions::interface_times); empty: the
  /// midpoints of the air intervals.
  std::vector<std::vector<Crossing>> crossings;
  std::string crossings_note;  ///< ThresholdCrossings::note
  /// Tip k's interfaces as event detection and the multi-tip pairing use them.
  [[nodiscard]] std::vector<Crossing> tip_crossings(std::size_t k) const;
};

/// The interfaces of every binarised tip timed at the threshold crossing.
struct ThresholdCrossings {
  std::vector<std::vector<Crossing>> tips;  ///< leading, trailing, further tips
  /// Which tips' fronts or rears kept their midpoints, and why ("" when none).
  std::string note;
};

/// An edge direction whose crossings' middle half spans less of a sample
/// holds no sub-sample time (edges sharper than a sample) and keeps its
/// midpoints, -. Sharp edges give a spread of noise only (libsynth's 2 us
/// rise at 20 kHz: 0.005-0.01); edges spanning a sample spread their
/// fractions over most of [0, 1] (0.5 for a linear ramp).
inline constexpr double least_crossing_spread = 0.1;

/// Every binarised tip's interfaces timed where its voltage crosses the level
/// that switched the phase (event_detection.hpp, item 9), from one more pass
/// over `recording` (rewound first); `b` is binarise_recording's result of
/// the same recording and options. Tips of a binary signal, and edge
/// directions sharper than a sample (least_crossing_spread), keep their
/// midpoints, and the note says so. Throws InputError naming the file when it
/// holds another number of frames than at binarisation (it changed while
/// being read).
ThresholdCrossings threshold_crossings(Recording& recording, const BinarisedRecording& b,
                                       const ProcessOptions& options);

/// FSCC and AWCC of the leading tip with one more trailing tip of a
/// multi-tip probe, as labs compare them with the bubble-by-bubble vector.
struct TipPairResult {
  std::size_t tip = 0;   ///< the trailing tip, an index into ProbeResult::geometry
  int channel = 0;
  double dx = 0.0, dy = 0.0;  ///< the pair's streamwise and cross-stream separation, m
  std::optional<FsccResult> fscc;
  std::optional<AwccResult> awcc;
};

/// A probe of four or more tips processed bubble by bubble (METHOD 11.3-11.6).
struct ProbeResult {
  /// The tips in processing order: leading (0), trailing (1), further tips.
  ProbeGeometry geometry;
  std::vector<int> channels;          ///< each tip's channel, same order
  std::vector<TipResult> further_tips;  ///< the phase statistics of tips 2, 3, ...
  /// Event detection's pairing of the leading tip with each trailing tip:
  /// the bubbles with their partners and each trailing tip's fate counts.
  ProbePairing pairing;
  /// The per-bubble vectors and their statistics; status too_few_bubbles
  /// with the pairing's message when the pairing was refused.
  MultiTipResult vectors;
  /// FSCC and AWCC of the leading tip with every trailing tip other than
  /// the pair's (ProcessResult::fscc and awcc), where it lies downstream.
  std::vector<TipPairResult> pairs;
  /// Whether the vectors can be trusted, by AWCC's levels: insufficient
  /// without statistics; low when FSCC of the leading tip with a trailing
  /// tip finds the trailing signal first or no delay (a channel mapped to
  /// the wrong tip), when the solver's caution is raised
  /// (MultiTipResult::caution), or when the mean vector's streamwise
  /// component and FSCC's velocity of the tip pair differ by more than their
  /// 95 % intervals allow together (the rule of awcc/assess.hpp): a bubble
  /// that misses a trailing tip is paired with an unrelated one, and the
  /// vectors of such pairs are wild but not all beyond the outlier cutoff.
  AwccQuality quality = AwccQuality::insufficient;
  std::string quality_reason;  ///< why not ok
};

struct ProcessResult {
  RecordingInfo info;
  double dx = 0.0, dy = 0.0;
  std::vector<TipResult> tips;        ///< leading tip first
  std::optional<FsccResult> fscc;
  std::optional<AwccResult> awcc;
  std::optional<StructureResult> structure;
  std::optional<VelocitySpectrum> spectrum;  ///< of AWCC's series, when AWCC ran
  std::optional<EventResult> events;  ///< event detection on the tip pair (options.events)
  std::optional<ProbeResult> probe;   ///< a multi-tip probe bubble by bubble (options.multi_tip)
  /// The leading tip's size distribution (options.sizes; awcc/position_sizes.hpp).
  std::optional<SizesResult> sizes;
  /// Dual-tip 4 F / u and the multi-tip estimate where there is one.
  InterfacialArea interfacial_area;
  /// Pairs of tips that hold one signal twice (BinarisedRecording::copies).
  std::vector<ChannelCopy> channel_copies;
  /// Every warning of the recording with its flag, in one list (awcc/assess.hpp
  /// assembles it; every output writes it).
  std::vector<Warning> warnings;
  double seconds = 0.0;               ///< wall time of the processing
  /// The SHA-256 of the recording's file when options.hash_input (the
  /// provenance's, Recording::sha256()); empty otherwise and for arrays.
  std::string input_sha256;

  /// The velocity of chord lengths and d32 (velocity_source()).
  [[nodiscard]] std::optional<double> velocity() const;
  /// AWCC's of quality ok; else FSCC's when defined; else AWCC's of low
  /// quality (flagged); else none (METHOD 4, item 10).
  [[nodiscard]] VelocitySource velocity_source() const;
  /// The 95 % sampling interval of velocity(), where its method gives one.
  [[nodiscard]] std::optional<Interval95> velocity_ci95() const;

  [[nodiscard]] std::string report() const;
};

/// Reads and binarises the two tips' channels. Throws InputError naming the
/// file and the problem (a tip failing the signal check, unless
/// signal_check.allow_bad_signal), OptionError for options that cannot work.
BinarisedRecording binarise_recording(const std::filesystem::path& path, const ProcessOptions& options);
/// The same from an open recording (read from its start; options.reader is not used).
BinarisedRecording binarise_recording(Recording& recording, const ProcessOptions& options);

/// Binary tip signals already in memory (a synthesis, a study, the
/// multi-tip validation) as a recording, built as binarise_recording builds
/// a binary file's: each tip's histogram holds its two levels (0 water, 1
/// air, one count per level), its threshold comes from that histogram by the
/// processing's rule (the trailing rule for every tip but the leading one),
/// and every tip gets the signal check under the options' policy (a failure
/// throws InputError naming the channel unless
/// signal_check.allow_bad_signal). The one way from signals to a recording,
/// so that a sweep row and pdp process of the file written from the same
/// signals see the same tips. signals[k] is the tip on channels[k] (leading,
/// trailing, further tips; 0, 1, 2, ... when channels is empty); positions,
/// m, one per signal where the probe's tips are known (else empty). fs and
/// frames come from the leading signal.
BinarisedRecording binary_recording(std::vector<AirIntervals> signals, const ProcessOptions& options,
                                    std::vector<int> channels = {}, std::vector<Vec3> positions = {});

/// Phase statistics (and FSCC, and AWCC on the binary signals) from binarised signals.
ProcessResult process_binarised(const BinarisedRecording& recording, const ProcessOptions& options);

/// What the raw-voltage correlations keep from record to record: FFT plans
/// (built once per size, used const) and scratch. Owned by the caller and
/// reused for the records it processes in turn, one per thread (not shared):
/// planning costs about as much as a record's transforms. A fresh one gives
/// the same numbers.
struct ProcessWorkspace {
  FftPlanCache plans;  ///< FSCC's
  AwccWorkspace awcc;  ///< AWCC's window correlations
};

/// AWCC correlating the raw voltages of the recording, windows from its
/// binarised leading tip (reads the file once more, block by block).
AwccResult awcc_raw(const std::filesystem::path& path, const BinarisedRecording& recording,
                    const ProcessOptions& options);
/// The same from the open recording the signals came from (read again from its start).
AwccResult awcc_raw(Recording& recording, const BinarisedRecording& binarised, const ProcessOptions& options);
/// The same with the caller's workspace.
AwccResult awcc_raw(Recording& recording, const BinarisedRecording& binarised, const ProcessOptions& options,
                    AwccWorkspace& workspace);

/// FSCC correlating the raw voltages of the recording (reads the file once
/// more, block by block; fscc_options.segments segments, S = 1 the whole record).
FsccResult fscc_raw(const std::filesystem::path& path, const BinarisedRecording& recording,
                    const ProcessOptions& options);
/// The same from the open recording the signals came from (read again from its start).
FsccResult fscc_raw(Recording& recording, const BinarisedRecording& binarised, const ProcessOptions& options);
/// The same with the caller's FFT plans.
FsccResult fscc_raw(Recording& recording, const BinarisedRecording& binarised, const ProcessOptions& options,
                    FftPlanCache& plans);

/// All of the above, as the options ask (awcc_options.signal chooses what
/// both FSCC and AWCC correlate).
ProcessResult process_recording(const std::filesystem::path& path, const ProcessOptions& options);
/// The same for an open recording (a file or arrays in memory), read from its start.
ProcessResult process_recording(Recording& recording, const ProcessOptions& options);
/// Both with the caller's workspace (records processed in turn share its plans).
ProcessResult process_recording(const std::filesystem::path& path, const ProcessOptions& options,
                                ProcessWorkspace& workspace);
ProcessResult process_recording(Recording& recording, const ProcessOptions& options, ProcessWorkspace& workspace);

}  // namespace awcc
