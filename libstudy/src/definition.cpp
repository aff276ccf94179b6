#include "definition.hpp"

#include <stdexcept>

#include "awcc/errors.hpp"
#include "synth/scene.hpp"

namespace study::detail {

bool is_scene_field(const std::string& name) {
  for (const auto& f : synth::scene_fields())
    if (f.name == name) return true;
  return false;
}

awcc::Dimension dimension_of(const std::string& name) {
  for (const auto& f : synth::scene_fields())
    if (f.name == name) return f.dimension;
  return awcc::Dimension::dimensionless;
}

std::vector<awcc::SettingTable> definition_tables(const std::filesystem::path& path,
                                                  const std::vector<std::string>& groups) {
  try {
    return awcc::read_setting_tables(path, groups);
  } catch (const awcc::InputError& e) {
    throw awcc::OptionError(e.what());
  }
}

std::uint64_t fnv1a(std::string_view text) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace study::detail
