// Synthetic recordings in pdp-sim's HDF5 layout (awcc/pdpsim_layout.hpp),
// so that pdp-sim's own tools (h5py: `signal` read as int8, `time`,
// `sensor_id`) and pdp's reader take the same file.
//
// Written block by block into datasets sized up front and chunked along the
// samples (64 Ki frames a chunk, whatever the block size, so the file's
// values do not depend on it); every dataset is deflated: `time` (float64,
// 8 bytes a frame, with shuffle) would otherwise outweigh a 0/1 signal of
// one byte per tip many times over.
#include <hdf5.h>

#include <algorithm>
#include <fmt/format.h>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "awcc/errors.hpp"
#include "awcc/pdpsim_layout.hpp"
#include "synth/recording.hpp"

namespace synth::detail {

namespace {

using awcc::pdpsim::hdf5_says;

constexpr hsize_t kChunkFrames = 1 << 16;
constexpr unsigned kDeflateLevel = 4;

// An identifier from libhdf5, released when the handle goes (the writer
// holds the library lock for as long as any handle lives).
class Handle {
 public:
  explicit Handle(hid_t id) : id_(id) {}
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, H5I_INVALID_HID)) {}
  Handle& operator=(Handle&&) = delete;
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { close(); }
  [[nodiscard]] hid_t get() const { return id_; }
  [[nodiscard]] bool valid() const { return id_ >= 0; }
  /// Releases now; false when libhdf5 reports a failure (for the file: its last writes).
  bool close() {
    const bool ok = id_ < 0 || H5Idec_ref(id_) >= 0;
    id_ = H5I_INVALID_HID;
    return ok;
  }

 private:
  hid_t id_;
};

}  // namespace

void write_hdf5(const std::filesystem::path& file, const std::filesystem::path& shown, const Scene& scene,
                std::span<const awcc::AirIntervals> signals, const RecordingOptions& options) {
  // Declared before every handle: they close under it, whatever the way out.
  const std::lock_guard lock(awcc::pdpsim::hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  auto fail = [&](const std::string& what) -> void {
    throw awcc::OutputError(fmt::format("{}: {}{}", shown.string(), what, hdf5_says()));
  };
  const std::size_t tips = signals.size();
  const std::int64_t frames = signals.front().sample_count;
  const bool binary = options.signal == SignalKind::binary;
  const auto n_frames = static_cast<hsize_t>(frames);
  const hsize_t chunk_frames = std::clamp<hsize_t>(n_frames, 1, kChunkFrames);

  Handle out(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT));
  if (!out.valid()) fail("cannot create the HDF5 file");

  // Room for the chunk being filled: blocks need not end on chunk boundaries.
  auto cache = [&](std::size_t chunk_bytes) {
    Handle dapl(H5Pcreate(H5P_DATASET_ACCESS));
    if (!dapl.valid() || H5Pset_chunk_cache(dapl.get(), 521, 2 * chunk_bytes + (1 << 20), 1.0) < 0) {
      fail("cannot set up the chunk cache");
    }
    return dapl;
  };
  auto compressed = [&](int rank, const hsize_t* chunk, bool shuffle) {
    Handle dcpl(H5Pcreate(H5P_DATASET_CREATE));
    if (!dcpl.valid() || H5Pset_chunk(dcpl.get(), rank, chunk) < 0 ||
        (shuffle && H5Pset_shuffle(dcpl.get()) < 0) || H5Pset_deflate(dcpl.get(), kDeflateLevel) < 0 ||
        H5Pset_fill_time(dcpl.get(), H5D_FILL_TIME_NEVER) < 0) {
      fail("cannot set up chunked, deflated storage");
    }
    return dcpl;
  };

  Handle time_space(H5Screate_simple(1, &n_frames, nullptr));
  Handle time_dcpl = compressed(1, &chunk_frames, true);
  Handle time_dapl = cache(chunk_frames * sizeof(double));
  Handle time(H5Dcreate2(out.get(), awcc::pdpsim::time_dataset, H5T_IEEE_F64LE, time_space.get(), H5P_DEFAULT,
                         time_dcpl.get(), time_dapl.get()));
  if (!time.valid()) fail("cannot create the dataset 'time'");

  const hsize_t signal_dims[2] = {n_frames, static_cast<hsize_t>(tips)};
  const hsize_t signal_chunk[2] = {chunk_frames, static_cast<hsize_t>(tips)};
  const std::size_t sample_bytes = binary ? 1 : 2;
  Handle signal_space(H5Screate_simple(2, signal_dims, nullptr));
  Handle signal_dcpl = compressed(2, signal_chunk, !binary);
  Handle signal_dapl = cache(chunk_frames * tips * sample_bytes);
  Handle signal(H5Dcreate2(out.get(), awcc::pdpsim::signal_dataset, binary ? H5T_STD_U8LE : H5T_STD_I16LE,
                           signal_space.get(), H5P_DEFAULT, signal_dcpl.get(), signal_dapl.get()));
  if (!signal.valid()) fail("cannot create the dataset 'signal'");

  auto attribute = [&](const char* name, hid_t file_type, hid_t memory_type, const void* value, hsize_t count,
                       bool scalar) {
    Handle space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &count, nullptr));
    Handle a(H5Acreate2(signal.get(), name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT));
    if (!space.valid() || !a.valid() || H5Awrite(a.get(), memory_type, value) < 0) {
      fail(fmt::format("cannot write the attribute '{}'", name));
    }
  };
  // pdp-sim's ids are its configuration's sensor ids (integers, h5py's int64); the tips are numbered here.
  std::vector<std::int64_t> ids(tips);
  for (std::size_t j = 0; j < tips; ++j) ids[j] = static_cast<std::int64_t>(j);
  attribute(awcc::pdpsim::sensor_id_attribute, H5T_STD_I64LE, H5T_NATIVE_INT64, ids.data(), tips, false);
  attribute(awcc::pdpsim::fs_attribute, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &scene.fs, 1, true);
  {
    // The tips' positions (m) by column, the key of pdp-sim's config.json, so
    // the file carries its probe (pdp process needs no declaration of it).
    std::vector<double> at;
    for (const auto& t : scene.probe_tips()) at.insert(at.end(), {t.x, t.y, t.z});
    const hsize_t dims[2] = {static_cast<hsize_t>(tips), 3};
    Handle space(H5Screate_simple(2, dims, nullptr));
    Handle a(space.valid() ? H5Acreate2(signal.get(), awcc::pdpsim::tip_position_attribute, H5T_IEEE_F64LE,
                                        space.get(), H5P_DEFAULT, H5P_DEFAULT)
                           : H5I_INVALID_HID);
    if (at.size() != 3 * tips || !a.valid() || H5Awrite(a.get(), H5T_NATIVE_DOUBLE, at.data()) < 0) {
      fail(fmt::format("cannot write the attribute '{}'", awcc::pdpsim::tip_position_attribute));
    }
  }
  std::optional<VoltageRenderer> renderer;
  if (!binary) {
    renderer.emplace(scene, tips);
    const double vpc = renderer->volts_per_count();
    attribute(awcc::pdpsim::volts_per_count_attribute, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &vpc, 1, true);
  }

  const std::int64_t block = std::max<std::int64_t>(1, options.block_frames);
  std::vector<std::vector<std::uint8_t>> air(tips, std::vector<std::uint8_t>(static_cast<std::size_t>(block)));
  std::vector<std::uint8_t> zero_one(binary ? static_cast<std::size_t>(block) * tips : 0);
  std::vector<std::int16_t> counts(binary ? 0 : static_cast<std::size_t>(block) * tips);
  std::vector<double> seconds(static_cast<std::size_t>(block));
  for (std::int64_t first = 0; first < frames; first += block) {
    const auto n = static_cast<std::size_t>(std::min(block, frames - first));
    std::vector<std::span<const std::uint8_t>> views;
    for (std::size_t j = 0; j < tips; ++j) {
      signals[j].render(first, std::span<std::uint8_t>(air[j].data(), n));
      views.emplace_back(air[j].data(), n);
    }
    if (renderer) {
      renderer->render(views, std::span<std::int16_t>(counts.data(), n * tips));
    } else {
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < tips; ++j) zero_one[i * tips + j] = air[j][i];
    }
    // i / fs from the frame's index, not by accumulation: the same value whatever the block.
    for (std::size_t i = 0; i < n; ++i) seconds[i] = static_cast<double>(first + static_cast<std::int64_t>(i)) / scene.fs;

    const hsize_t start[2] = {static_cast<hsize_t>(first), 0};
    const hsize_t extent[2] = {static_cast<hsize_t>(n), static_cast<hsize_t>(tips)};
    Handle memory2(H5Screate_simple(2, extent, nullptr));
    Handle memory1(H5Screate_simple(1, extent, nullptr));
    if (H5Sselect_hyperslab(signal_space.get(), H5S_SELECT_SET, start, nullptr, extent, nullptr) < 0 ||
        H5Dwrite(signal.get(), binary ? H5T_NATIVE_UINT8 : H5T_NATIVE_INT16, memory2.get(), signal_space.get(),
                 H5P_DEFAULT, binary ? static_cast<const void*>(zero_one.data()) : counts.data()) < 0 ||
        H5Sselect_hyperslab(time_space.get(), H5S_SELECT_SET, start, nullptr, extent, nullptr) < 0 ||
        H5Dwrite(time.get(), H5T_NATIVE_DOUBLE, memory1.get(), time_space.get(), H5P_DEFAULT, seconds.data()) < 0) {
      fail(fmt::format("writing frames {} to {} failed", first, first + static_cast<std::int64_t>(n)));
    }
    if (options.progress) {
      options.progress(static_cast<double>(first + static_cast<std::int64_t>(n)) / static_cast<double>(frames));
    }
  }
  // Closing flushes the chunks still in the caches: its failure is a write failure.
  if (!signal.close() || !time.close()) fail("writing the last chunks failed");
  if (H5Fflush(out.get(), H5F_SCOPE_LOCAL) < 0 || !out.close()) fail("closing the file failed");
}

}  // namespace synth::detail
