// pdp._pdp: the compiled core of the Python module (python/pdp/__init__.py
// is the documented interface). Every computation is the libraries': options
// are applied from their declarations (awcc::process_options), results are
// their JSON forms (awcc/serialise.hpp) turned into Python objects by the
// json module, so a dict from Python equals the JSON `pdp process` writes.
// Long calls release the GIL; library errors become pdp.InputError and
// pdp.OptionError (ValueError subclasses) carrying the library's message and
// the setting that fixes them.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/flags.hpp"
#include "awcc/json_text.hpp"
#include "awcc/options.hpp"
#include "awcc/process.hpp"
#include "awcc/profile_flow.hpp"
#include "awcc/read_back.hpp"
#include "awcc/serialise.hpp"
#include "awcc/version.hpp"
#include "correction/model.hpp"
#include "correction/profile_rows.hpp"
#include "correction/rows.hpp"
#include "synth/recording.hpp"
#include "synth/scene.hpp"
#include "synth/sidecar.hpp"
#include "study/profile_run.hpp"
#include "synth/synthesiser.hpp"

namespace py = pybind11;

namespace {

using Settings = std::vector<std::pair<std::string, std::string>>;

// Keyword options as settings by declared name (python/pdp/__init__.py maps
// filter_a to filter-a); a preset is the setting "preset".
std::vector<awcc::OptionSetting> option_settings(const Settings& settings, const std::string& preset = {}) {
  std::vector<awcc::OptionSetting> out;
  for (const auto& [name, value] : settings) out.push_back({name, value, {}});
  if (!preset.empty()) out.push_back({"preset", preset, {}});
  return out;
}

py::object python_of(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(awcc::json_text(j));
}

// --- arrays in -------------------------------------------------------------

// How a channel's dtype is read: 16-bit counts (bool, int8, uint8, int16),
// other integers as counts in floats, floating values as volts.
enum class SampleKind { counts16, counts, volts };

SampleKind kind_of(const py::array& a, std::size_t k) {
  const char kind = a.dtype().kind();
  const auto size = a.dtype().itemsize();
  if (kind == 'f') return SampleKind::volts;
  if (kind == 'b' || (kind == 'i' && size <= 2) || (kind == 'u' && size == 1)) return SampleKind::counts16;
  if (kind == 'i' || kind == 'u') return SampleKind::counts;
  throw awcc::OptionError(fmt::format("channel {}: samples of dtype {} cannot be read; give float (volts) or integer "
                                      "(counts) samples",
                                      k, py::str(a.dtype()).cast<std::string>()),
                          "channels");
}

// A channel's samples where numpy keeps them: the first byte, the stride
// between samples in bytes, the dtype (kind and size, native byte order).
struct ChannelView {
  const char* data;
  py::ssize_t stride;
  char kind;
  py::ssize_t size;
  double scale;  // volts per count for counts, 1 for volts

  // Kinds and sizes read in place; others (float16, long double) are first
  // converted by numpy.
  static bool readable(char kind, py::ssize_t size) {
    if (kind == 'f') return size == 4 || size == 8;
    if (kind == 'b') return size == 1;
    return (kind == 'i' || kind == 'u') && (size == 1 || size == 2 || size == 4 || size == 8);
  }

  // Calls f(sample) with sample(i) the i-th sample as the dtype's C type.
  template <class F>
  void visit(F&& f) const {
    auto as = [&](auto zero) {
      using T = decltype(zero);
      // memcpy: numpy does not promise alignment (a view into a record array).
      f([this](std::size_t i) {
        T v;
        std::memcpy(&v, data + static_cast<py::ssize_t>(i) * stride, sizeof v);
        return v;
      });
    };
    if (kind == 'f') {
      if (size == 4) return as(float{});
      if (size == 8) return as(double{});
    } else if (kind == 'b') {
      return as(bool{});
    } else if (kind == 'i') {
      if (size == 1) return as(std::int8_t{});
      if (size == 2) return as(std::int16_t{});
      if (size == 4) return as(std::int32_t{});
      if (size == 8) return as(std::int64_t{});
    } else if (kind == 'u') {
      if (size == 1) return as(std::uint8_t{});
      if (size == 2) return as(std::uint16_t{});
      if (size == 4) return as(std::uint32_t{});
      if (size == 8) return as(std::uint64_t{});
    }
    throw awcc::OptionError(fmt::format("samples of kind '{}' and {} bytes cannot be read", kind, size), "channels");
  }
};

// The channels (1-D arrays of one length) as an in-memory recording.
// Integer counts are volts x volts_per_count when it is given, else counts of
// unknown scale (a 0/1 binary signal).
std::unique_ptr<awcc::Recording> recording_of(const std::vector<py::array>& channels, double fs,
                                              std::optional<double> volts_per_count) {
  if (channels.empty()) throw awcc::OptionError("no channel: give the tips' signals", "channels");
  std::vector<SampleKind> kinds;
  for (std::size_t k = 0; k < channels.size(); ++k) {
    if (channels[k].ndim() != 1) {
      throw awcc::OptionError(fmt::format("channel {} has {} dimensions; give 1-D arrays, one per tip (or a 2-D "
                                          "array samples x channels)",
                                          k, channels[k].ndim()),
                              "channels");
    }
    if (channels[k].shape(0) != channels[0].shape(0)) {
      throw awcc::OptionError(fmt::format("channel {} has {} samples but channel 0 has {}; give arrays of one length",
                                          k, channels[k].shape(0), channels[0].shape(0)),
                              "channels");
    }
    kinds.push_back(kind_of(channels[k], k));
  }
  if (volts_per_count && !(*volts_per_count > 0.0)) {
    throw awcc::OptionError(fmt::format("volts_per_count = {}: give a positive scale", *volts_per_count),
                            "volts-per-count");
  }
  // Integer samples are a digitiser's counts: without their scale a threshold
  // in counts would be printed as volts and the signal check's levels would
  // be meaningless. Only a 0/1 (or boolean) phase signal needs none.
  for (std::size_t k = 0; k < channels.size() && !volts_per_count; ++k) {
    if (kinds[k] == SampleKind::volts || channels[k].dtype().kind() == 'b' || channels[k].size() == 0) continue;
    const auto lo = channels[k].attr("min")().cast<double>(), hi = channels[k].attr("max")().cast<double>();
    if (lo >= 0.0 && hi <= 1.0) continue;
    throw awcc::OptionError(
        fmt::format("channel {} holds integer samples ({}, {} to {}): integers are a digitiser's counts, whose volts "
                    "pdp cannot guess; give volts_per_count=... (V per count, the digitiser's range over its "
                    "counts), or float samples in volts",
                    k, py::str(channels[k].dtype()).cast<std::string>(), lo, hi),
        "volts-per-count");
  }
  const auto n = static_cast<std::size_t>(channels[0].shape(0));
  const auto c = channels.size();
  const bool all16 = std::all_of(kinds.begin(), kinds.end(), [](SampleKind k) { return k == SampleKind::counts16; });
  const bool any_counts = std::any_of(kinds.begin(), kinds.end(), [](SampleKind k) { return k != SampleKind::volts; });
  const double quantum = volts_per_count.value_or(1.0);
  const bool volts_known = volts_per_count.has_value() || !any_counts;
  // Each channel read where it lies (any stride, a column of a 2-D array
  // too) in its own dtype; only a foreign byte order is converted first, by
  // numpy, under the GIL. The interleaving then runs without the GIL: for a
  // long record it is hundreds of MB written, and a fresh page faulted in
  // per 4 kB held every other Python thread for a third of a second.
  std::vector<py::array> kept;  // the converted copies, alive until the copy is done
  std::vector<ChannelView> views;
  for (std::size_t k = 0; k < c; ++k) {
    py::array a = channels[k];
    if (!a.dtype().attr("isnative").cast<bool>() || !ChannelView::readable(a.dtype().kind(), a.dtype().itemsize())) {
      a = a.dtype().kind() == 'f' ? py::array(py::array_t<double, py::array::forcecast>::ensure(a))
                                  : py::array(py::array_t<std::int64_t, py::array::forcecast>::ensure(a));
      kept.push_back(a);
    }
    views.push_back({static_cast<const char*>(a.data()), a.strides(0), a.dtype().kind(), a.dtype().itemsize(),
                     kinds[k] == SampleKind::volts ? 1.0 : quantum});
  }
  py::gil_scoped_release unlocked;
  if (all16) {
    std::vector<std::int16_t> interleaved(n * c);
    for (std::size_t k = 0; k < c; ++k) {
      views[k].visit([&](auto sample) {
        for (std::size_t i = 0; i < n; ++i) interleaved[i * c + k] = static_cast<std::int16_t>(sample(i));
      });
    }
    return awcc::memory_recording(std::move(interleaved), static_cast<int>(c), fs, quantum, volts_known);
  }
  std::vector<float> interleaved(n * c);
  for (std::size_t k = 0; k < c; ++k) {
    const double scale = views[k].scale;
    views[k].visit([&](auto sample) {
      // As numpy's cast to float64, then the scale, then float: the numbers
      // of the earlier forcecast copy.
      for (std::size_t i = 0; i < n; ++i) {
        interleaved[i * c + k] = static_cast<float>(static_cast<double>(sample(i)) * scale);
      }
    });
  }
  return awcc::memory_recording(std::move(interleaved), static_cast<int>(c), fs);
}

// --- arrays out ------------------------------------------------------------

py::array_t<std::int64_t> intervals_array(const awcc::AirIntervals& s) {
  py::array_t<std::int64_t> out({static_cast<py::ssize_t>(s.intervals.size()), py::ssize_t{2}});
  auto m = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < s.intervals.size(); ++i) {
    m(static_cast<py::ssize_t>(i), 0) = s.intervals[i].start;
    m(static_cast<py::ssize_t>(i), 1) = s.intervals[i].stop;
  }
  return out;
}

// A table of one row per window or bubble as a dict of arrays, one per
// declared column (awcc/serialise.hpp: the CSV's columns): a float64 array
// for a numeric column (NaN where a row has no value), an array of str for
// the text one. The declarations are the one owner of names and order.
template <class Columns, class Rows>
py::dict table_of(const Columns& columns, const Rows& rows) {
  py::dict out;
  for (const auto& column : columns) {
    if (column.text) {
      py::list cells;
      for (const auto& row : rows) cells.append(py::str(std::string(column.text(row))));
      out[py::str(std::string(column.name))] = py::module_::import("numpy").attr("array")(cells, "U");
    } else {
      py::array_t<double> values(static_cast<py::ssize_t>(rows.size()));
      auto m = values.mutable_unchecked<1>();
      for (std::size_t i = 0; i < rows.size(); ++i) m(static_cast<py::ssize_t>(i)) = column.value(rows[i]);
      out[py::str(std::string(column.name))] = values;
    }
  }
  return out;
}

// Each table's columns with their units ("" for text), for the DataFrames' attrs.
template <class Columns>
py::list units_of(const Columns& columns) {
  py::list out;
  for (const auto& column : columns) out.append(py::make_tuple(std::string(column.name), std::string(column.unit)));
  return out;
}

// The window table (awcc::awcc_window_columns) as a dict of arrays.
py::dict windows_of(const awcc::AwccResult& r) { return table_of(awcc::awcc_window_columns(), r.windows); }

py::array_t<double> array_of(const std::vector<double>& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

// What the JSON does not hold: the functions behind its scales, as
// --correlation-functions and --spectrum write them (R11 and R12 against the
// lag, s, NaN where a function has no value; Welch's PSD of AWCC's velocity
// series), and the per-bubble tables, as --bubbles writes them.
py::dict detail_of(const awcc::ProcessResult& r) {
  py::dict out;
  out["correlation"] = py::none();
  out["spectrum"] = py::none();
  if (r.fscc && !(r.fscc->r11.empty() && r.fscc->r12.empty())) {
    const auto& f = *r.fscc;
    const auto n11 = static_cast<std::int64_t>(f.r11.size()), n12 = static_cast<std::int64_t>(f.r12.size());
    const std::int64_t first = std::min(f.r11_first_lag, f.r12_first_lag);
    const std::int64_t last = std::max(f.r11_first_lag + n11, f.r12_first_lag + n12) - 1;
    std::vector<double> lag, r11, r12;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (std::int64_t k = first; k <= last; ++k) {
      lag.push_back(static_cast<double>(k) / r.info.fs);
      const std::int64_t j11 = k - f.r11_first_lag, j12 = k - f.r12_first_lag;
      r11.push_back(j11 >= 0 && j11 < n11 ? f.r11[static_cast<std::size_t>(j11)] : nan);
      r12.push_back(j12 >= 0 && j12 < n12 ? f.r12[static_cast<std::size_t>(j12)] : nan);
    }
    out["correlation"] = py::dict(py::arg("lag") = array_of(lag), py::arg("r11") = array_of(r11),
                                  py::arg("r12") = array_of(r12));
  }
  if (r.spectrum && r.spectrum->status == awcc::SpectrumStatus::ok) {
    const auto& v = *r.spectrum;
    out["spectrum"] = py::dict(py::arg("frequency") = array_of(v.psd.frequency),
                               py::arg("density") = array_of(v.psd.density),
                               py::arg("resolvable_frequency") = v.resolvable_frequency);
  }
  // The per-bubble tables, where their method ran: event detection's one row
  // per leading bubble, the multi-tip probe's one vector row per leading bubble.
  out["bubbles"] = r.events ? py::object(table_of(awcc::event_bubble_columns(), r.events->bubbles)) : py::none();
  out["vectors"] =
      r.probe ? py::object(table_of(awcc::multi_tip_bubble_columns(), r.probe->vectors.bubbles)) : py::none();
  return out;
}

// (JSON object, window table or None, detail arrays).
py::tuple result_of(const awcc::ProcessResult& r) {
  return py::make_tuple(python_of(awcc::to_json(r)), r.awcc ? py::object(windows_of(*r.awcc)) : py::none(),
                        detail_of(r));
}

// --- the functions ---------------------------------------------------------

template <class T>
void describe(py::list& out, const char* group, std::span<const awcc::OptionField<T>> fields, const T& defaults) {
  for (const auto& f : fields) {
    py::dict d;
    d["group"] = group;
    d["name"] = std::string(f.name);
    d["unit"] = std::string(f.unit);
    d["help"] = std::string(f.help);
    d["default"] = f.format(defaults);
    d["flag"] = f.flag;
    out.append(d);
  }
}

py::list options() {
  py::list out;
  const awcc::ProcessOptions p;
  describe(out, "probe and methods", awcc::process_option_fields(), p);
  describe(out, "input", awcc::reader_option_fields(), p.reader);
  describe(out, "binarisation", awcc::binarisation_option_fields(), p.binarisation);
  describe(out, "fscc", awcc::fscc_option_fields(), p.fscc_options);
  describe(out, "awcc", awcc::awcc_option_fields(), p.awcc_options);
  describe(out, "structure", awcc::structure_option_fields(), p.structure);
  describe(out, "event detection", awcc::event_option_fields(), p.event_options);
  describe(out, "multi-tip", awcc::multi_tip_option_fields(), p.multi_tip_options);
  describe(out, "flow", awcc::profile_flow_option_fields(), awcc::ProfileFlowOptions{});
  const synth::Scene scene;
  for (const auto& f : synth::scene_fields()) {
    py::dict d;
    d["group"] = "scene";
    d["name"] = std::string(f.name);
    d["unit"] = std::string(awcc::si_unit(f.dimension));
    d["help"] = std::string(f.help);
    d["default"] = f.format(scene);
    d["flag"] = false;
    out.append(d);
  }
  return out;
}

py::tuple read_recording(const std::filesystem::path& path, const Settings& settings) {
  const auto o = awcc::process_options(option_settings(settings));
  std::vector<float> samples;
  awcc::RecordingInfo info;
  {
    py::gil_scoped_release unlocked;
    auto recording = awcc::open_recording(path, o.reader);
    info = recording->info();
    const auto c = static_cast<std::size_t>(info.channels);
    if (info.frames > 0) samples.reserve(static_cast<std::size_t>(info.frames) * c);
    std::vector<float> block(static_cast<std::size_t>(o.block_frames) * c);
    for (;;) {
      const auto n = recording->read(block, o.block_frames);
      if (n == 0) break;
      samples.insert(samples.end(), block.begin(), block.begin() + n * static_cast<std::int64_t>(c));
    }
  }
  const auto c = static_cast<py::ssize_t>(info.channels);
  const auto frames = static_cast<py::ssize_t>(samples.size()) / std::max<py::ssize_t>(c, 1);
  py::array_t<float> data({frames, c});
  std::copy(samples.begin(), samples.end(), data.mutable_data());
  py::dict meta;
  meta["file"] = info.path.string();
  meta["format"] = info.description;
  meta["channels"] = info.channels;
  meta["fs"] = info.fs;
  meta["samples"] = frames;
  meta["quantum"] = info.quantum;
  meta["volts_known"] = info.volts_known;
  meta["warnings"] = info.warnings;
  meta["channel_names"] = info.channel_names;
  return py::make_tuple(data, info.fs, meta);
}

// One array passed twice (the module pairs a tip with itself to binarise
// one tip): no copied channel to look for (SignalCheckOptions::find_copies).
bool one_array_twice(const std::vector<py::array>& channels) {
  return channels.size() == 2 && channels[0].ptr() == channels[1].ptr();
}

py::dict binarise(const std::vector<py::array>& channels, double fs, std::optional<double> volts_per_count,
                  const Settings& settings) {
  auto o = awcc::process_options(option_settings(settings));
  o.signal_check.find_copies = !one_array_twice(channels);
  auto recording = recording_of(channels, fs, volts_per_count);
  awcc::BinarisedRecording b;
  {
    py::gil_scoped_release unlocked;
    b = awcc::binarise_recording(*recording, o);
  }
  py::dict out;
  out["sample_count"] = b.leading.sample_count;
  out["fs"] = b.info.fs;
  out["leading"] = py::dict(py::arg("intervals") = intervals_array(b.leading),
                            py::arg("threshold") = python_of(awcc::to_json(b.leading_threshold)));
  out["trailing"] = py::dict(py::arg("intervals") = intervals_array(b.trailing),
                             py::arg("threshold") = python_of(awcc::to_json(b.trailing_threshold)));
  return out;
}

py::tuple process_arrays(const std::vector<py::array>& channels, double fs, std::optional<double> volts_per_count,
                         const Settings& settings, const std::string& preset) {
  auto o = awcc::process_options(option_settings(settings, preset));
  o.signal_check.find_copies = !one_array_twice(channels);
  auto recording = recording_of(channels, fs, volts_per_count);
  awcc::ProcessResult r;
  {
    py::gil_scoped_release unlocked;
    r = awcc::process_recording(*recording, o);
  }
  return result_of(r);
}

// One recording as `pdp process FILE --json` gives it (provenance added by the caller).
py::tuple process_file(const std::filesystem::path& path, const Settings& settings, const std::string& preset) {
  auto o = awcc::process_options(option_settings(settings, preset));
  awcc::ProcessResult r;
  {
    py::gil_scoped_release unlocked;
    // A synthetic recording's sidecar states its volts per count, as for pdp process.
    if (!(o.reader.volts_per_count > 0.0)) {
      if (const auto vpc = synth::sidecar_volts_per_count(path)) o.reader.volts_per_count = *vpc;
    }
    r = awcc::process_recording(path, o);
  }
  return result_of(r);
}

// A profile run (study::process_profile, as pdp process runs it): the JSON
// of the rows with their corrections and the flow, each row's detail, and
// the warnings to issue. positions: one per file (m), or empty.
py::tuple process_profile(const std::vector<std::string>& paths, const std::vector<double>& positions,
                          const Settings& settings, const std::string& preset, const std::string& model_path,
                          const Settings& flow_settings, bool as_profile) {
  study::ProfileRunOptions o;
  o.processing = awcc::process_options(option_settings(settings, preset));
  o.flow = awcc::profile_flow_options(option_settings(flow_settings));
  std::optional<correction::CorrectionModel> model;
  study::ProfileRun run;
  {
    py::gil_scoped_release unlocked;
    if (!model_path.empty()) model = correction::CorrectionModel::load(model_path);
    o.model = model ? &*model : nullptr;
    std::vector<std::optional<double>> at(positions.begin(), positions.end());
    run = study::process_profile(paths, at, o);
  }
  run.single = !as_profile;  // a list of one file is a profile of one row, as before
  py::list windows, details;
  for (const auto& r : run.results) {
    windows.append(r.awcc ? py::object(windows_of(*r.awcc)) : py::none());
    details.append(detail_of(r));
  }
  nlohmann::json flow_json;
  std::string flow_report;
  if (run.flow) {
    flow_json = awcc::to_json(*run.flow);
    flow_report = run.flow->report();
  }
  return py::make_tuple(python_of(study::profile_run_json(run, std::filesystem::path(model_path).filename().string())),
                        windows, details, run.warnings(), run.flow ? python_of(flow_json) : py::object(py::none()),
                        flow_report, run.inputs);
}

py::object provenance(const std::vector<std::string>& inputs, const Settings& settings, const std::string& preset,
                      const std::string& call) {
  const auto o = awcc::process_options(option_settings(settings, preset));
  nlohmann::json j;
  {
    py::gil_scoped_release unlocked;
    // Hashed here: process_file's reading is over by the time Python asks.
    std::vector<awcc::ProvenanceInput> files;
    for (const auto& f : inputs) files.push_back({f, {}});
    j = awcc::provenance_json(o, files, call);
  }
  return python_of(j);
}

py::tuple correct(const std::string& json, const std::filesystem::path& model_path, std::optional<double> dx,
                  std::optional<double> dy, std::optional<int> np) {
  correction::RowDefaults defaults;
  defaults.dx = dx;
  defaults.dy = dy;
  defaults.np = np;
  correction::FileCorrection fc;
  {
    py::gil_scoped_release unlocked;
    const auto model = correction::CorrectionModel::load(model_path);
    fc = correction::correct_process_json(model, json, defaults, "results", model_path.filename().string());
  }
  return py::make_tuple(py::module_::import("json").attr("loads")(fc.text), fc.warnings);
}

py::dict synthesise(const Settings& settings, const std::string& signal) {
  synth::Scene scene;
  const auto given = option_settings(settings);
  std::vector<bool> used(given.size(), false);
  awcc::apply_settings(synth::scene_fields(), std::span<const awcc::OptionSetting>(given), scene, used);
  for (std::size_t i = 0; i < given.size(); ++i) {
    if (!used[i]) throw awcc::OptionError(fmt::format("unknown scene field '{}'", given[i].name), given[i].name);
  }
  if (const auto validation = scene.validate(); !validation.ok()) throw synth::invalid_scene(validation);
  if (signal != "binary" && signal != "voltage") {
    throw awcc::OptionError(fmt::format("signal = {}: give binary or voltage", signal), "signal");
  }
  synth::Synthesis s;
  {
    py::gil_scoped_release unlocked;
    s = synth::synthesise(scene);
  }
  const auto tips = s.signals.size();
  const std::int64_t n = tips ? s.signals[0].sample_count : 0;
  py::dict out;
  out["fs"] = scene.fs;
  out["scene"] = python_of(synth::scene_to_json(scene));
  out["truth"] = python_of(synth::truth_to_json(s.truth));
  out["generator_version"] = awcc::generator_version;
  if (signal == "binary") {
    py::array_t<std::uint8_t> data({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(tips)});
    auto* p = data.mutable_data();
    {
      py::gil_scoped_release unlocked;
      std::vector<std::uint8_t> column(static_cast<std::size_t>(n));
      for (std::size_t j = 0; j < tips; ++j) {
        s.signals[j].render(0, column);
        for (std::size_t i = 0; i < column.size(); ++i) p[i * tips + j] = column[i];
      }
    }
    out["signals"] = data;
    out["volts_per_count"] = py::none();
  } else {
    py::array_t<std::int16_t> data({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(tips)});
    synth::VoltageRenderer renderer(scene, tips);
    {
      py::gil_scoped_release unlocked;
      // Rendered block by block as the recording writer does: the same counts.
      const std::int64_t block = synth::RecordingOptions{}.block_frames;
      std::vector<std::vector<std::uint8_t>> air(tips, std::vector<std::uint8_t>(static_cast<std::size_t>(block)));
      for (std::int64_t first = 0; first < n; first += block) {
        const auto m = static_cast<std::size_t>(std::min(block, n - first));
        std::vector<std::span<const std::uint8_t>> spans;
        for (std::size_t j = 0; j < tips; ++j) {
          s.signals[j].render(first, std::span<std::uint8_t>(air[j].data(), m));
          spans.emplace_back(air[j].data(), m);
        }
        renderer.render(spans, std::span<std::int16_t>(data.mutable_data() + first * static_cast<std::int64_t>(tips),
                                                       m * tips));
      }
    }
    out["signals"] = data;
    out["volts_per_count"] = renderer.volts_per_count();
  }
  return out;
}

// A profile's flow quantities (awcc/profile_flow.hpp) from a process JSON's
// or profile CSV's text, its rows read back by correction::profile_rows_of_*
// (the one row builder): {"flow": the JSON's flow object or None, "why_none":
// why the file has no profile's flow, "report", "warnings"}.
py::dict profile_flow(const std::string& text, const std::string& file, const Settings& settings) {
  const auto options = awcc::profile_flow_options(option_settings(settings));
  py::dict out;
  correction::ProfileRowsRead read;
  std::optional<awcc::ProfileFlowResult> flow;
  {
    py::gil_scoped_release unlocked;
    const auto first = text.find_first_not_of(" \t\r\n");
    if (first != std::string::npos && (text[first] == '{' || text[first] == '[')) {
      nlohmann::json j;
      try {
        j = nlohmann::json::parse(text);
      } catch (const nlohmann::json::parse_error& e) {
        throw awcc::InputError(fmt::format("{}: not valid JSON ({}); give a pdp process JSON or profile CSV", file,
                                           e.what()));
      }
      read = correction::profile_rows_of_json(j, file);
    } else {
      read = correction::profile_rows_of_csv(text, file);
    }
    if (read.why_none.empty()) flow = correction::profile_flow_of(std::move(read.rows), options);
  }
  out["flow"] = flow ? python_of(awcc::to_json(*flow)) : py::object(py::none());
  out["why_none"] = read.why_none;
  out["report"] = flow ? flow->report() : std::string();
  out["warnings"] = flow ? flow->warnings() : std::vector<std::string>{};
  return out;
}

// c(y) of a fitted air-concentration model (awcc::ConcentrationModel, the
// one owner of its formula), named by its key in the flow JSON, at every y (m).
py::array_t<double> concentration_curve(const std::string& kind, double diffusivity, double y90,
                                        const py::array_t<double, py::array::c_style | py::array::forcecast>& y) {
  awcc::ConcentrationModel model;
  if (kind == awcc::process_key::smooth_chute) {
    model.kind = awcc::ConcentrationModelKind::smooth_chute;
  } else if (kind == awcc::process_key::stepped_chute) {
    model.kind = awcc::ConcentrationModelKind::stepped_chute;
  } else {
    throw awcc::OptionError(fmt::format("'{}' is not an air-concentration model: give {} or {}", kind,
                                        awcc::process_key::smooth_chute, awcc::process_key::stepped_chute),
                            "model");
  }
  model.diffusivity = diffusivity;
  model.y90 = y90;
  py::array_t<double> out(y.request().shape);
  const auto* in = y.data();
  auto* values = out.mutable_data();
  for (py::ssize_t i = 0; i < y.size(); ++i) values[i] = model(in[i]);
  return out;
}

// The keyword of a declared option: its name with underscores. The one
// place the module spells the libraries' option names.
std::string keyword_of(std::string name) {
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

bool declared(std::string_view name) {
  auto in = [&](auto fields) {
    return std::any_of(fields.begin(), fields.end(), [&](const auto& f) { return f.name == name; });
  };
  return in(awcc::process_option_fields()) || in(awcc::reader_option_fields()) ||
         in(awcc::binarisation_option_fields()) || in(awcc::fscc_option_fields()) ||
         in(awcc::awcc_option_fields()) || in(awcc::structure_option_fields()) || in(awcc::event_option_fields()) ||
         in(awcc::multi_tip_option_fields()) || in(awcc::profile_flow_option_fields()) || in(synth::scene_fields());
}

// Library errors as Python exceptions with the library's message, the
// keyword(s) that fix them appended (as the command line appends its flag),
// and in `quantity` the declared name(s) of the option(s).
void translate(const char* type, std::string message, const std::string& quantity) {
  std::string keywords;
  for (const auto& name : awcc::split_cells(quantity)) {
    if (declared(name)) keywords += (keywords.empty() ? "" : ", ") + keyword_of(name);
  }
  if (!keywords.empty()) message += fmt::format(" (keyword {})", keywords);
  const auto error = py::module_::import("pdp._errors").attr(type)(message);
  error.attr("quantity") = quantity.empty() ? py::object(py::none()) : py::object(py::str(quantity));
  PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
}

}  // namespace

PYBIND11_MODULE(_pdp, m) {
  m.doc() = "The compiled core of pdp (use the pdp package, whose functions are documented)";
  m.attr("version") = awcc::version;
  m.attr("generator_version") = awcc::generator_version;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const awcc::InputError& e) {
      translate("InputError", e.what(), e.quantity());
    } catch (const awcc::OptionError& e) {
      translate("OptionError", e.what(), e.quantity());
    } catch (const awcc::OutputError& e) {
      translate("OutputError", e.what(), {});
    }
  });
  m.def("profile_columns", [](bool correction) {
    // The profile CSV's columns and then, when the CSV holds a correction, the
    // correction's, as the libraries declare them.
    py::list out;
    auto add = [&](std::span<const awcc::ProfileColumn> columns) {
      for (const auto& c : columns) {
        py::list values;
        for (const auto v : awcc::written_values(c.name)) values.append(std::string(v));
        out.append(py::dict(py::arg("name") = std::string(c.name), py::arg("unit") = std::string(c.unit),
                            py::arg("pointer") = std::string(c.json_pointer), py::arg("meaning") = std::string(c.meaning),
                            py::arg("values") = values));
      }
    };
    add(awcc::profile_csv_columns());
    if (correction) add(correction::correction_csv_columns());
    return out;
  }, py::arg("correction"));
  m.def("table_units", [] {
    // (name, unit) of each column of the windows, bubbles and vectors tables.
    return py::dict(py::arg("windows") = units_of(awcc::awcc_window_columns()),
                    py::arg("bubbles") = units_of(awcc::event_bubble_columns()),
                    py::arg("vectors") = units_of(awcc::multi_tip_bubble_columns()));
  });
  m.def("flow_quantities", [] {
    // The profile quantities, each once (awcc/profile_flow.hpp, flow_quantity_names).
    py::list out;
    for (const auto& q : awcc::flow_quantity_names) {
      out.append(py::dict(py::arg("pointer") = std::string(q.pointer), py::arg("symbol") = std::string(q.symbol),
                          py::arg("unit") = std::string(q.unit), py::arg("meaning") = std::string(q.meaning),
                          py::arg("shown_unit") = std::string(q.shown_unit), py::arg("shown_scale") = q.shown_scale));
    }
    return out;
  });
  m.def("flags", [] {
    // The codes a result's "flags" may hold, with their meanings (awcc/flags.hpp).
    py::list out;
    for (const auto& f : awcc::flag_names) {
      out.append(py::dict(py::arg("code") = std::string(f.code), py::arg("meaning") = std::string(f.meaning)));
    }
    return out;
  });
  // What FSCC's and AWCC's intervals cover, as the summary says it (one sentence, for the report).
  m.attr("sampling_intervals_only") = std::string(awcc::sampling_intervals_only);
  m.def("options", &options);
  m.def("read", &read_recording, py::arg("path"), py::arg("settings"));
  m.def("binarise", &binarise, py::arg("channels"), py::arg("fs"), py::arg("volts_per_count"), py::arg("settings"));
  m.def("process_arrays", &process_arrays, py::arg("channels"), py::arg("fs"), py::arg("volts_per_count"),
        py::arg("settings"), py::arg("preset"));
  m.def("process_file", &process_file, py::arg("path"), py::arg("settings"), py::arg("preset"));
  m.def("process_profile", &process_profile, py::arg("paths"), py::arg("positions"), py::arg("settings"),
        py::arg("preset"), py::arg("model"), py::arg("flow_settings"), py::arg("as_profile"));
  m.def("provenance", &provenance, py::arg("inputs"), py::arg("settings"), py::arg("preset"), py::arg("call"));
  m.def("correct", &correct, py::arg("json"), py::arg("model"), py::arg("dx"), py::arg("dy"), py::arg("np"));
  m.def("synthesise", &synthesise, py::arg("settings"), py::arg("signal"));
  m.def("profile_flow", &profile_flow, py::arg("text"), py::arg("file"), py::arg("settings"));
  m.def("concentration_curve", &concentration_curve, py::arg("kind"), py::arg("diffusivity"), py::arg("y90"),
        py::arg("y"));
  m.def("repeated_position", [](const std::vector<double>& y, const std::vector<std::string>& names) {
    return awcc::repeated_position(y, names);
  }, py::arg("y"), py::arg("names"));
}
