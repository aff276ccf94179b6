#pragma once
// What the definition files of sweeps and designs share (private to the
// library): scene fields by name, the tables of a file, and the id of a
// definition's canonical text.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "awcc/settings_file.hpp"
#include "awcc/units.hpp"

namespace study::detail {

/// True for a scene field's name (synth::scene_fields).
bool is_scene_field(const std::string& name);
/// A scene field's dimension; dimensionless for any other name (np, anisotropy).
awcc::Dimension dimension_of(const std::string& name);
/// The tables of a definition file: a file that cannot be read is a
/// definition that cannot be run (awcc::OptionError naming the file).
std::vector<awcc::SettingTable> definition_tables(const std::filesystem::path& path,
                                                  const std::vector<std::string>& groups = {});
/// 64-bit FNV-1a of a text.
std::uint64_t fnv1a(std::string_view text);
/// The id of a definition: FNV-1a of its canonical text, halved so that it
/// reads back as a signed 64-bit number.
inline std::uint64_t definition_id(std::string_view canonical) { return fnv1a(canonical) >> 1; }

}  // namespace study::detail
