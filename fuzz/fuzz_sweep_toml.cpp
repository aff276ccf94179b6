// The sweep definition parser and its expansion on arbitrary text.
#include <stdexcept>

#include "fuzz_util.hpp"
#include "study/sweep.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::scratch("sweep.toml");
  fuzz::write(path, data, size);
  try {
    const auto d = study::load_sweep(path);
    std::size_t combinations = 1;
    for (const auto& [k, v] : d.grid) combinations *= v.size();
    if (d.repeat * static_cast<std::int64_t>(combinations) < 10000 && d.runs * d.repeat < 10000) {
      const auto runs = d.expand();
      for (const auto& r : runs) (void)study::sweep_row(r, nullptr, "x", study::study_id(d), awcc::AwccOptions{});
    }
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  std::filesystem::remove(path);
  return 0;
}
