#include "synth/sidecar.hpp"

#include <fstream>

#include "awcc/random.hpp"
#include "awcc/version.hpp"

namespace synth {

using nlohmann::json;

namespace {

json optional_number(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

json vec(const Vec3& v) { return json::array({v.x, v.y, v.z}); }

}  // namespace

json scene_to_json(const Scene& s) {
  json tips = json::array();
  for (const auto& t : s.probe_tips()) tips.push_back(vec(t));
  return json{
      {"velocity", s.velocity},
      {"tu", s.tu},
      {"tu_y", s.tu_y},
      {"tu_z", s.tu_z},
      {"time_scale", json::array({s.time_scale_of(0), s.time_scale_of(1), s.time_scale_of(2)})},
      {"rho_xy", s.rho_xy},
      {"rho_xz", s.rho_xz},
      {"rho_yz", s.rho_yz},
      {"void_fraction", s.void_fraction},
      {"bubble_diameter", s.bubble_diameter},
      {"diameter_log_sd", s.diameter_log_sd},
      {"aspect_ratio", s.aspect_ratio},
      {"arrival", std::string(to_string(s.arrival))},
      {"overlap", std::string(to_string(s.overlap))},
      {"overlap_retries", s.overlap_retries},
      {"dx", s.dx},
      {"dy", s.dy},
      {"dz", s.dz},
      {"tips", tips},
      {"fs", s.fs},
      {"duration", s.duration},
      {"seed", s.seed},
      {"velocity_update", std::string(to_string(s.velocity_update))},
      {"realisation_step", s.effective_realisation_step()},
      {"voltage_water", s.voltage_water},
      {"voltage_air", s.voltage_air},
      {"voltage_time_constant", s.voltage_time_constant},
      {"voltage_noise", s.voltage_noise},
      {"voltage_full_scale", s.voltage_full_scale},
  };
}

json truth_to_json(const Truth& t) {
  const Scene& s = t.imposed;
  const auto& r = t.realised;
  json void_fraction = json::array(), pierced = json::array(), chords = json::array(), area = json::array();
  for (const auto& tip : t.tips) {
    void_fraction.push_back(tip.void_fraction);
    pierced.push_back(tip.bubbles_pierced);
    chords.push_back(tip.chords);
    area.push_back(optional_number(tip.interfacial_area));
  }
  json pairs = json::array();
  for (const auto& p : t.pairs) {
    pairs.push_back({{"tips", json::array({p.first, p.second})}, {"pierced_by_both", p.pierced_by_both}});
  }
  json scales = json::array();
  for (const auto& v : r.integral_time_scale) scales.push_back(optional_number(v));
  return json{
      {"imposed",
       {{"mean_velocity", json::array({s.velocity, 0.0, 0.0})},
        {"turbulence_intensity", json::array({s.tu, s.tu_y, s.tu_z})},
        {"integral_time_scale", json::array({s.time_scale_of(0), s.time_scale_of(1), s.time_scale_of(2)})},
        {"rho_xy", s.rho_xy},
        {"rho_xz", s.rho_xz},
        {"rho_yz", s.rho_yz},
        {"void_fraction", s.void_fraction},
        {"dispersed_phase", std::string(to_string(t.dispersed_phase))},
        {"bubble_diameter", s.bubble_diameter},
        {"pierce_rate", t.expected_pierce_rate},
        {"interfacial_area", t.expected_interfacial_area}}},
      {"realised",
       {{"mean_velocity", r.mean_velocity},
        {"rms_velocity", r.rms_velocity},
        {"turbulence_intensity", r.turbulence_intensity},
        {"integral_time_scale", scales},
        {"rho_xy", optional_number(r.rho_xy)},
        {"rho_xz", optional_number(r.rho_xz)},
        {"rho_yz", optional_number(r.rho_yz)},
        {"void_fraction", void_fraction},
        {"bubbles_pierced", pierced},
        {"chords", chords},
        {"interfacial_area", area},
        {"pierced_by_both", pairs},
        {"bubbles_generated", t.bubbles_generated},
        {"overlaps_unresolved", t.overlaps_unresolved},
        {"compensated_volume_fraction", t.compensated_volume_fraction},
        {"reentries_missed", t.reentries_missed},
        {"velocity_steps", r.steps}}},
      {"realisation_step", t.realisation_step},
      {"control_volume", json::array({t.control_volume[0], t.control_volume[1], t.control_volume[2]})},
      {"bubble_rate", t.bubble_rate},
      {"sample_count", t.sample_count},
  };
}

json sidecar_json(const Truth& truth, const RecordingOptions& options, const std::filesystem::path& recording,
                  const BubbleTruth* bubbles) {
  json out = truth_to_json(truth);
  json tips = json::array();
  for (const auto& tip : truth.tips) tips.push_back(vec(tip.position));
  out["toolkit"] = {{"name", "pdp"}, {"version", awcc::version}};
  out["recording"] = {{"file", recording.filename().string()},
                      {"format", std::string(to_string(options.format))},
                      {"signal", std::string(to_string(options.signal))},
                      {"channels", truth.tips.size()},
                      // The .h5 writer stores a binary signal as uint8 (hdf5_recording.cpp).
                      {"sample_type", options.format == FileFormat::hdf5 && options.signal == SignalKind::binary
                                          ? "uint8"
                                          : "int16"},
                      {"volts_per_count", options.signal == SignalKind::voltage
                                              ? json(truth.imposed.voltage_full_scale / 32768.0)
                                              : json(nullptr)}};
  out["scene"] = scene_to_json(truth.imposed);
  out["probe"] = {{"tips", tips}, {"leading_tip", 0}};
  out["bubble_truth"] = bubbles ? json{{"file", bubble_truth_path(recording).filename().string()},
                                        {"bubbles", bubbles->size()},
                                        {"columns", bubble_truth_columns(bubbles->tip_count)}}
                                  : json(nullptr);
  out["fs"] = truth.imposed.fs;
  out["seed"] = truth.imposed.seed;
  out["generator_version"] = awcc::generator_version;
  return out;
}

std::filesystem::path sidecar_path(const std::filesystem::path& recording) {
  std::filesystem::path p = recording;
  p.replace_extension();
  p += ".truth.json";
  return p;
}

std::filesystem::path bubble_truth_path(const std::filesystem::path& recording) {
  return sidecar_path(recording).replace_extension(".bubbles.csv");
}

std::optional<double> sidecar_volts_per_count(const std::filesystem::path& recording) {
  std::ifstream in(sidecar_path(recording));
  if (!in) return std::nullopt;
  try {
    const auto j = nlohmann::json::parse(in);
    const auto& v = j.at("recording").at("volts_per_count");
    if (v.is_number() && v.get<double>() > 0.0) return v.get<double>();
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

}  // namespace synth
