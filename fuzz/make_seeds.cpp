// Writes the seeds of the reader targets (fuzz_read.cpp): a few small valid
// files of each format, each behind the byte that chooses the reader options
// (see fuzz_read.cpp), into DIR/fuzz_read_<format>/. Audio, HDF5 and MATLAB
// files are written through the libraries labs write them with (libsndfile,
// libhdf5, matio); UQ .dat, raw, CSV, LabVIEW .lvm and TDMS byte by byte
// from their descriptions (awcc/recording.hpp, NI's "TDMS File Format
// Internal Structure"). Every file stays under 20 KB: the fuzzer mutates
// small inputs fastest. The signals are a probe's: two levels (water 0.3 V,
// air 4.1 V), the trailing tip a few samples behind the leading one, 10 kHz.
// Usage: fuzz_make_seeds DIR
#include <hdf5.h>
#include <matio.h>
#include <sndfile.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace {

namespace fs = std::filesystem;
using Bytes = std::string;

constexpr double kRate = 10000.0;
// Selector bits (fuzz_read.cpp): 1 a stated 10 kHz rate, 4 allow_truncated, 8 volts per count.
constexpr std::uint8_t kStated = 1, kTruncated = 4, kVolts = 8, kNamed = 16;

fs::path root;

// Tip `tip`'s voltage at sample i: bubbles of a few samples, the trailing tip 3 samples late.
double volts(std::size_t i, int tip) {
  const std::size_t k = i + 1000 - static_cast<std::size_t>(3 * tip);
  return (k % 37 < 6 || k % 53 < 4) ? 4.1 : 0.3;
}

void put(const std::string& target, const std::string& name, std::uint8_t selector, const Bytes& file) {
  const fs::path dir = root / ("fuzz_read_" + target);
  fs::create_directories(dir);
  std::ofstream out(dir / name, std::ios::binary | std::ios::trunc);
  out.put(static_cast<char>(selector));
  out.write(file.data(), static_cast<std::streamsize>(file.size()));
}

Bytes slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Written by a library to a scratch file, then taken in as bytes.
fs::path scratch(const std::string& name) { return root / (".scratch-" + name); }

template <class T>
void append(Bytes& b, T v) {
  char c[sizeof(T)];
  std::memcpy(c, &v, sizeof(T));
  b.append(c, sizeof(T));
}
template <class T>
void append_be(Bytes& b, T v) {
  char c[sizeof(T)];
  std::memcpy(c, &v, sizeof(T));
  for (std::size_t i = sizeof(T); i-- > 0;) b.push_back(c[i]);
}

std::int16_t counts(double v) { return static_cast<std::int16_t>(v * 32768.0 / 5.0); }

// ---------------------------------------------------------------------------

void dat() {
  for (const auto& [rows, channels, selector] : {std::tuple{900, 2, kStated}, std::tuple{300, 3, kStated},
                                                 std::tuple{200, 1, std::uint8_t(kStated | kVolts)}}) {
    Bytes b;
    append<std::int32_t>(b, rows);
    append<std::int32_t>(b, channels);
    for (int i = 0; i < rows; ++i) {
      for (int c = 0; c < channels; ++c) append(b, counts(volts(static_cast<std::size_t>(i), c)));
    }
    put("dat", std::to_string(channels) + "ch.dat", selector, b);
  }
}

void raw() {
  // Selector bits 3-7: type (int16, int32, float32, float64), big-endian, channels - 1.
  const auto selector = [](int type, bool big, int channels) {
    return static_cast<std::uint8_t>(kStated | type << 3 | (big ? 1 : 0) << 5 | (channels - 1) << 6);
  };
  const auto write = [&](int type, bool big, int channels, int frames, const std::string& name) {
    Bytes b;
    for (int i = 0; i < frames; ++i) {
      for (int c = 0; c < channels; ++c) {
        const double v = volts(static_cast<std::size_t>(i), c);
        const double count = v * 1000.0;  // 1 mV per count (fuzz_read.cpp)
        switch (type) {
          case 0: big ? append_be(b, static_cast<std::int16_t>(count)) : append(b, static_cast<std::int16_t>(count)); break;
          case 1: big ? append_be(b, static_cast<std::int32_t>(count)) : append(b, static_cast<std::int32_t>(count)); break;
          case 2: big ? append_be(b, static_cast<float>(count)) : append(b, static_cast<float>(count)); break;
          default: big ? append_be(b, count) : append(b, count); break;
        }
      }
    }
    put("raw", name, selector(type, big, channels), b);
  };
  write(0, false, 2, 1000, "int16-le-2ch.raw");
  write(1, true, 3, 300, "int32-be-3ch.raw");
  write(2, false, 2, 500, "float32-le-2ch.raw");
  write(3, true, 1, 400, "float64-be-1ch.raw");
}

void csv() {
  const auto table = [](const std::string& head, char sep, bool time, bool comma_decimal, int rows,
                        const std::string& trailer) {
    std::string s = head;
    char cell[64];
    for (int i = 0; i < rows; ++i) {
      std::string row;
      if (time) {
        std::snprintf(cell, sizeof cell, "%.4f%c", i / kRate, sep);
        row += cell;
      }
      std::snprintf(cell, sizeof cell, "%.3f%c%.3f", volts(static_cast<std::size_t>(i), 0), sep,
                    volts(static_cast<std::size_t>(i), 1));
      row += cell;
      if (comma_decimal) {
        for (auto& ch : row) {
          if (ch == '.') ch = ',';
        }
      }
      s += row + trailer + "\n";
    }
    return s;
  };
  put("csv", "time.csv", kStated, table("time,lead,trail\n", ',', true, false, 400, ""));
  put("csv", "semicolon-decimal-comma.csv", kStated, table("", ';', false, true, 400, ""));
  put("csv", "tab-t.tsv", 0, table("t\tA\tB\n", '\t', true, false, 300, ""));
  // LabVIEW's text (.lvm): a file header, a segment header with Delta_X, rows
  // with and without the empty Comment cell.
  const std::string lvm_head =
      "LabVIEW Measurement\t\nWriter_Version\t2\nReader_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n"
      "Multi_Headings\tNo\nX_Columns\tOne\nTime_Pref\tRelative\nOperator\tlab\nDate\t2024/05/02\n"
      "Time\t10:00:00.0\n***End_of_Header***\t\n\nChannels\t2\t\nSamples\t300\t300\t\n"
      "Date\t2024/05/02\t2024/05/02\t\nTime\t10:00:00.0\t10:00:00.0\t\nX_Dimension\tTime\tTime\t\n"
      "X0\t0.0000000000000000E+0\t0.0000000000000000E+0\t\nDelta_X\t1.000000E-4\t1.000000E-4\t\n"
      "***End_of_Header***\t\nX_Value\tVoltage\tVoltage_0\tComment\n";
  put("csv", "labview-comment.lvm", 0, table(lvm_head, '\t', true, false, 300, "\t"));
  put("csv", "labview.lvm", 0, table(lvm_head, '\t', true, false, 300, ""));
}

void sndfile() {
  struct Audio {
    const char* name;
    int format, channels, frames;
    std::uint8_t selector;
  };
  const Audio audio[] = {
      {"pcm16.wav", SF_FORMAT_WAV | SF_FORMAT_PCM_16, 2, 2000, 0},
      {"float.wav", SF_FORMAT_WAV | SF_FORMAT_FLOAT, 2, 1000, kStated},
      {"pcm24.aiff", SF_FORMAT_AIFF | SF_FORMAT_PCM_24, 2, 1000, kVolts},
      {"pcm16.flac", SF_FORMAT_FLAC | SF_FORMAT_PCM_16, 2, 4000, 0},
      {"pcm32.w64", SF_FORMAT_W64 | SF_FORMAT_PCM_32, 2, 800, 0},
      {"pcm16.rf64", SF_FORMAT_RF64 | SF_FORMAT_PCM_16, 3, 800, 0},
      {"double.caf", SF_FORMAT_CAF | SF_FORMAT_DOUBLE, 1, 800, 0},
      {"ulaw.au", SF_FORMAT_AU | SF_FORMAT_ULAW, 2, 1500, 0},
  };
  for (const auto& a : audio) {
    SF_INFO info{};
    info.samplerate = static_cast<int>(kRate);
    info.channels = a.channels;
    info.format = a.format;
    const fs::path p = scratch(a.name);
    SNDFILE* f = sf_open(p.c_str(), SFM_WRITE, &info);
    if (!f) {
      std::fprintf(stderr, "fuzz_make_seeds: libsndfile cannot write %s: %s\n", a.name, sf_strerror(nullptr));
      std::exit(1);
    }
    std::vector<double> v;
    for (int i = 0; i < a.frames; ++i) {
      for (int c = 0; c < a.channels; ++c) v.push_back(volts(static_cast<std::size_t>(i), c) / 5.0);
    }
    sf_writef_double(f, v.data(), a.frames);
    sf_close(f);
    put("sndfile", a.name, a.selector, slurp(p));
    fs::remove(p);
  }
  // A WAV cut short: its header promises more than it holds (allow_truncated).
  const Bytes whole = slurp(root / "fuzz_read_sndfile" / "pcm16.wav").substr(1);
  put("sndfile", "cut.wav", kTruncated, whole.substr(0, whole.size() - 1000));
}

// ---------------------------------------------------------------------------
// TDMS: segments of a 28-byte lead-in, metadata (objects and properties) and raw data.

Bytes tdms_string(const std::string& s) {
  Bytes b;
  append<std::uint32_t>(b, static_cast<std::uint32_t>(s.size()));
  return b + s;
}

struct TdmsProperty {
  std::string name;
  std::uint32_t type;  // 0x20 string, 10 float64, 3 int32
  std::string text;
  double number = 0.0;
};

Bytes tdms_object(const std::string& path, std::uint32_t raw_index, std::uint32_t type, std::uint64_t count,
                  const std::vector<TdmsProperty>& properties) {
  Bytes b = tdms_string(path);
  append<std::uint32_t>(b, raw_index);
  if (raw_index == 20) {
    append<std::uint32_t>(b, type);
    append<std::uint32_t>(b, 1);  // dimension
    append<std::uint64_t>(b, count);
  }
  append<std::uint32_t>(b, static_cast<std::uint32_t>(properties.size()));
  for (const auto& p : properties) {
    b += tdms_string(p.name);
    append<std::uint32_t>(b, p.type);
    if (p.type == 0x20) {
      b += tdms_string(p.text);
    } else if (p.type == 3) {
      append<std::int32_t>(b, static_cast<std::int32_t>(p.number));
    } else {
      append<double>(b, p.number);
    }
  }
  return b;
}

Bytes tdms_segment(std::uint32_t toc, std::uint32_t objects, const Bytes& meta_objects, const Bytes& raw) {
  Bytes meta;
  if (toc & (1u << 1)) {
    append<std::uint32_t>(meta, objects);
    meta += meta_objects;
  }
  Bytes b = "TDSm";
  append<std::uint32_t>(b, toc);
  append<std::uint32_t>(b, 4713);
  append<std::uint64_t>(b, meta.size() + raw.size());
  append<std::uint64_t>(b, meta.size());
  return b + meta + raw;
}

void tdms() {
  constexpr std::uint32_t meta = 1u << 1, new_list = 1u << 2, raw = 1u << 3, interleaved = 1u << 5;
  const TdmsProperty increment{"wf_increment", 10, "", 1.0 / kRate};
  const auto root_and_group = tdms_object("/", 0xFFFFFFFFu, 0, 0, {{"name", 0x20, "probe", 0}}) +
                              tdms_object("/'probe'", 0xFFFFFFFFu, 0, 0, {});
  // int16 counts, one channel after the other, scaled by NI's linear scale.
  {
    const std::vector<TdmsProperty> scale{increment,
                                          {"NI_Scaling_Status", 0x20, "unscaled", 0},
                                          {"NI_Number_Of_Scales", 3, "", 2},
                                          {"NI_Scale[1]_Scale_Type", 0x20, "Linear", 0},
                                          {"NI_Scale[1]_Linear_Slope", 10, "", 5.0 / 32768},
                                          {"NI_Scale[1]_Linear_Y_Intercept", 10, "", 0.0}};
    const int n = 600;
    Bytes data;
    for (int c = 0; c < 2; ++c) {
      for (int i = 0; i < n; ++i) append(data, counts(volts(static_cast<std::size_t>(i), c)));
    }
    const Bytes objects = root_and_group + tdms_object("/'probe'/'lead'", 20, 2, n, scale) +
                          tdms_object("/'probe'/'trail'", 20, 2, n, scale);
    put("tdms", "int16-scaled.tdms", kNamed, tdms_segment(meta | new_list | raw, 4, objects, data));
  }
  // float64 volts, interleaved, in two segments: the second reuses the
  // first's object list (no metadata), as LabVIEW appends blocks.
  {
    const int n = 300;
    Bytes data;
    for (int i = 0; i < n; ++i) {
      for (int c = 0; c < 2; ++c) append<double>(data, volts(static_cast<std::size_t>(i), c));
    }
    const Bytes objects = root_and_group + tdms_object("/'probe'/'a'", 20, 10, n, {increment}) +
                          tdms_object("/'probe'/'b'", 20, 10, n, {increment});
    put("tdms", "float64-interleaved-2seg.tdms", kStated,
        tdms_segment(meta | new_list | raw | interleaved, 4, objects, data) +
            tdms_segment(raw | interleaved, 0, {}, data));
  }
  // float32 and int32 channels, a second segment that states the same raw
  // index again (raw index 0) for one and adds data; no rate: a stated one.
  {
    const int n = 250;
    Bytes a, b;
    for (int i = 0; i < n; ++i) append<float>(a, static_cast<float>(volts(static_cast<std::size_t>(i), 0)));
    for (int i = 0; i < n; ++i) append<std::int32_t>(b, counts(volts(static_cast<std::size_t>(i), 1)));
    const Bytes first = root_and_group + tdms_object("/'probe'/'f'", 20, 9, n, {}) +
                        tdms_object("/'probe'/'i'", 20, 3, n, {});
    Bytes again = tdms_object("/'probe'/'f'", 0, 0, 0, {}) + tdms_object("/'probe'/'i'", 0, 0, 0, {});
    put("tdms", "float32-int32-reuse.tdms", kStated | kVolts,
        tdms_segment(meta | new_list | raw, 4, first, a + b) + tdms_segment(meta | raw, 2, again, a + b));
  }
}

// ---------------------------------------------------------------------------

void h5_write(hid_t where, const char* name, hid_t type, const std::vector<hsize_t>& dims, const void* data,
              bool deflate) {
  const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
  if (deflate) {
    std::vector<hsize_t> chunk = dims;
    chunk[0] = std::min<hsize_t>(chunk[0], 256);
    H5Pset_chunk(plist, static_cast<int>(chunk.size()), chunk.data());
    H5Pset_deflate(plist, 6);
  }
  const hid_t set = H5Dcreate2(where, name, type, space, H5P_DEFAULT, plist, H5P_DEFAULT);
  H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
  H5Dclose(set);
  H5Pclose(plist);
  H5Sclose(space);
}

void h5_attribute(hid_t where, const char* name, double value) {
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(where, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_DOUBLE, &value);
  H5Aclose(a);
  H5Sclose(space);
}

void hdf5() {
  // pdp-sim's layout: `signal` (uint8 0/1, samples x sensors) with sensor_id, and `time`.
  {
    const fs::path p = scratch("pdpsim.h5");
    const hid_t f = H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const std::size_t n = 1000;
    std::vector<std::uint8_t> signal;
    std::vector<double> time;
    for (std::size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 2; ++c) signal.push_back(volts(i, c) > 1.0 ? 1 : 0);
      time.push_back(static_cast<double>(i) / kRate);
    }
    h5_write(f, "signal", H5T_NATIVE_UINT8, {n, 2}, signal.data(), false);
    h5_write(f, "time", H5T_NATIVE_DOUBLE, {n}, time.data(), false);
    const hid_t set = H5Dopen2(f, "signal", H5P_DEFAULT);
    const std::int32_t ids[2] = {1, 2};
    const hsize_t two = 2;
    const hid_t space = H5Screate_simple(1, &two, nullptr);
    const hid_t a = H5Acreate2(set, "sensor_id", H5T_NATIVE_INT32, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_INT32, ids);
    H5Aclose(a);
    H5Sclose(space);
    H5Dclose(set);
    H5Fclose(f);
    put("hdf5", "pdpsim.h5", 0, slurp(p));
    fs::remove(p);
  }
  // int16 counts, one 1-D dataset per channel in a group with an fs
  // attribute, chunked and deflated, with a volts_per_count attribute.
  {
    const fs::path p = scratch("group.h5");
    const hid_t f = H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t g = H5Gcreate2(f, "run", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    h5_attribute(g, "fs", kRate);
    const std::size_t n = 1500;
    for (int c = 0; c < 2; ++c) {
      std::vector<std::int16_t> v;
      for (std::size_t i = 0; i < n; ++i) v.push_back(counts(volts(i, c)));
      const std::string name = c == 0 ? "lead" : "trail";
      h5_write(g, name.c_str(), H5T_NATIVE_INT16, {n}, v.data(), true);
      const hid_t set = H5Dopen2(g, name.c_str(), H5P_DEFAULT);
      h5_attribute(set, "volts_per_count", 5.0 / 32768);
      H5Dclose(set);
    }
    H5Gclose(g);
    H5Fclose(f);
    put("hdf5", "group-deflate.h5", kStated | kNamed, slurp(p));
    fs::remove(p);
  }
  // The file's only 2-D dataset, float32 volts, channels x samples (read
  // transposed), with a dt attribute.
  {
    const fs::path p = scratch("volts.h5");
    const hid_t f = H5Fcreate(p.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const std::size_t n = 1200;
    std::vector<float> v;
    for (int c = 0; c < 2; ++c) {
      for (std::size_t i = 0; i < n; ++i) v.push_back(static_cast<float>(volts(i, c)));
    }
    h5_write(f, "volts", H5T_NATIVE_FLOAT, {2, n}, v.data(), false);
    const hid_t set = H5Dopen2(f, "volts", H5P_DEFAULT);
    h5_attribute(set, "dt", 1.0 / kRate);
    H5Dclose(set);
    H5Fclose(f);
    put("hdf5", "transposed-dt.h5", 0, slurp(p));
    fs::remove(p);
  }
}

// ---------------------------------------------------------------------------

void mat_variable(mat_t* file, const char* name, matio_classes cls, matio_types type, std::size_t rows,
                  std::size_t columns, void* data, matio_compression z) {
  std::size_t dims[2] = {rows, columns};
  matvar_t* v = Mat_VarCreate(name, cls, type, 2, dims, data, MAT_F_DONT_COPY_DATA);
  Mat_VarWrite(file, v, z);
  Mat_VarFree(v);
}

void mat() {
  const std::size_t n = 800;
  // Column-major: samples x channels.
  std::vector<double> volts2;
  for (int c = 0; c < 2; ++c) {
    for (std::size_t i = 0; i < n; ++i) volts2.push_back(volts(i, c));
  }
  std::vector<double> time;
  for (std::size_t i = 0; i < n; ++i) time.push_back(static_cast<double>(i) / kRate);
  double fs = kRate;
  struct Mat {
    const char* name;
    mat_ft version;
    matio_compression z;
    std::uint8_t selector;
  };
  const Mat files[] = {{"v5.mat", MAT_FT_MAT5, MAT_COMPRESSION_NONE, 0},
                       {"v5-zlib.mat", MAT_FT_MAT5, MAT_COMPRESSION_ZLIB, 0},
                       {"v73.mat", MAT_FT_MAT73, MAT_COMPRESSION_NONE, 0}};
  for (const auto& m : files) {
    const fs::path p = scratch(m.name);
    mat_t* file = Mat_CreateVer(p.c_str(), nullptr, m.version);
    if (!file) {
      std::fprintf(stderr, "fuzz_make_seeds: matio cannot write %s\n", m.name);
      std::exit(1);
    }
    mat_variable(file, "volts", MAT_C_DOUBLE, MAT_T_DOUBLE, n, 2, volts2.data(), m.z);
    mat_variable(file, "fs", MAT_C_DOUBLE, MAT_T_DOUBLE, 1, 1, &fs, m.z);
    Mat_Close(file);
    put("mat", m.name, m.selector, slurp(p));
    fs::remove(p);
  }
  // int16 counts, one vector per channel (named: selector bit 4), one
  // compressed, and a time vector; the rate from it.
  {
    const fs::path p = scratch("vectors.mat");
    mat_t* file = Mat_CreateVer(p.c_str(), nullptr, MAT_FT_MAT5);
    std::vector<std::int16_t> a, b;
    for (std::size_t i = 0; i < n; ++i) {
      a.push_back(counts(volts(i, 0)));
      b.push_back(counts(volts(i, 1)));
    }
    mat_variable(file, "t", MAT_C_DOUBLE, MAT_T_DOUBLE, n, 1, time.data(), MAT_COMPRESSION_NONE);
    mat_variable(file, "lead", MAT_C_INT16, MAT_T_INT16, n, 1, a.data(), MAT_COMPRESSION_ZLIB);
    mat_variable(file, "trail", MAT_C_INT16, MAT_T_INT16, n, 1, b.data(), MAT_COMPRESSION_NONE);
    Mat_Close(file);
    put("mat", "int16-vectors-time.mat", kVolts | kNamed, slurp(p));
    fs::remove(p);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_make_seeds DIR\n");
    return 2;
  }
  root = argv[1];
  fs::create_directories(root);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  dat();
  raw();
  csv();
  sndfile();
  tdms();
  hdf5();
  mat();
  return 0;
}
