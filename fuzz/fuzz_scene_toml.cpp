// The scene TOML parser and validation on arbitrary text; valid scenes that
// are small enough are synthesised too.
#include <stdexcept>

#include "fuzz_util.hpp"
#include "synth/scene.hpp"
#include "synth/synthesiser.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::scratch("scene.toml");
  fuzz::write(path, data, size);
  try {
    synth::Scene s;
    synth::load_scene_toml(path, s);
    if (s.validate().ok() && s.sample_count() < 200000 && s.duration / s.effective_realisation_step() < 200000 &&
        s.duration * s.void_fraction * s.velocity / s.bubble_diameter < 20000) {
      const auto out = synth::synthesise(s);
      for (const auto& sig : out.signals) {
        if (!sig.check().empty()) __builtin_trap();  // invalid intervals: a real bug
      }
    }
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  std::filesystem::remove(path);
  return 0;
}
