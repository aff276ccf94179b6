// Model files (awcc/correction.hpp): a valid small model is edited byte by
// byte as the input says, its length field and CRC are repaired (so that the
// edits reach the structural checks instead of stopping at the checksum),
// and the result is parsed; a model that parses must correct without
// crashing. The input: triples (offset u16, value u8); a first byte with the
// top bit set also truncates the file.
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "correction/model.hpp"

namespace {

std::vector<std::uint8_t> make_seed() {
  std::mt19937_64 g(1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  correction::TrainingData v;
  v.features = correction::Features::count;
  correction::CorrectionModel m;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < v.features; ++j) v.x.push_back(u(g));
    v.y.push_back(u(g));
  }
  for (int j = 0; j < v.features; ++j) m.ranges.push_back({correction::Features::names[static_cast<std::size_t>(j)], 0.0, 1.0});
  correction::ForestOptions o;
  o.trees = 3;
  o.min_leaf = 3;
  o.threads = 1;
  m.velocity = correction::QuantileForest::train(v, o);
  m.turbulence_intensity = correction::QuantileForest::train(v, o);
  m.provenance = "fuzz";
  return m.serialise();
}

const std::vector<std::uint8_t> seed = make_seed();

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto bytes = seed;
  std::size_t at = 0;
  if (size > 0 && (data[0] & 0x80u)) {
    const std::size_t keep = 24 + (static_cast<std::size_t>(data[0] & 0x7fu) * bytes.size()) / 128;
    if (keep < bytes.size()) bytes.resize(keep);
    at = 1;
  }
  for (; at + 3 <= size; at += 3) {
    const std::size_t offset = (static_cast<std::size_t>(data[at]) | static_cast<std::size_t>(data[at + 1]) << 8) % bytes.size();
    bytes[offset] = data[at + 2];
  }
  if (bytes.size() >= 24) {
    const std::uint64_t length = bytes.size() - 24;
    for (int i = 0; i < 8; ++i) bytes[12 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(length >> (8 * i));
    const auto crc = correction::crc32(bytes.data(), bytes.size() - 4);
    for (int i = 0; i < 4; ++i) bytes[bytes.size() - 4 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(crc >> (8 * i));
  }
  try {
    const auto m = correction::CorrectionModel::parse(bytes, "fuzz.qrf");
    correction::Features f;
    for (double v : {0.0, 0.5, 1.0}) {
      f.velocity = f.turbulence_intensity = f.void_fraction = f.d32 = f.dx = f.dy = f.np = v;
      f.windows_accepted = 1000;
      (void)m.correct(f);
    }
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
