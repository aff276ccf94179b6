#include <algorithm>
#include "correction/features.hpp"

#include <fmt/format.h>
#include <stdexcept>
#include <tuple>

#include "awcc/velocity_series.hpp"

namespace correction {

std::string_view to_string(CorrectionStatus status) {
  switch (status) {
    case CorrectionStatus::corrected: return "corrected";
    case CorrectionStatus::awcc_not_run: return "awcc_not_run";
    case CorrectionStatus::no_awcc_velocity: return "no_awcc_velocity";
    case CorrectionStatus::no_bubbles: return "no_bubbles";
    case CorrectionStatus::missing_feature: return "missing_feature";
    case CorrectionStatus::too_few_windows: return "too_few_windows";
    case CorrectionStatus::outside_training_range: return "outside_training_range";
    case CorrectionStatus::probe_corrected: return "probe_corrected";
    case CorrectionStatus::awcc_not_measured: return "awcc_not_measured";
    case CorrectionStatus::untrusted: return "untrusted";
  }
  return "unknown";
}

FeatureUnit unit_of(std::string_view feature) {
  if (feature == "velocity" || feature == "fscc_velocity") return {"m/s", 1.0};
  if (feature == "d32" || feature == "fscc_d32" || feature == "dx" || feature == "dy") return {"mm", 1e3};
  if (feature == "fs") return {"kHz", 1e-3};
  if (feature == "duration") return {"s", 1.0};
  if (feature == "chord_time" || feature == "fscc_lag") return {"ms", 1e3};
  if (feature == Features::lag_name) return {"samples", 1.0};
  return {"-", 1.0};
}

namespace {
std::string number_with_unit(double v, FeatureUnit u) {
  return u.unit == "-" ? fmt::format("{:.4g}", v * u.scale) : fmt::format("{:.4g} {}", v * u.scale, u.unit);
}
}  // namespace

std::string feature_value_text(std::string_view feature, double value) {
  return fmt::format("{} = {}", feature, number_with_unit(value, unit_of(feature)));
}

std::string feature_range_text(std::string_view feature, double min, double max) {
  const auto u = unit_of(feature);
  return fmt::format("{:.4g}-{}", min * u.scale, number_with_unit(max, u));
}

FeatureResult make_features(const Measurement& m) {
  FeatureResult r;
  auto& f = r.features;
  // What every forest shares, and FSCC's own.
  f.void_fraction = m.void_fraction;
  f.dx = m.dx;
  f.dy = m.dy;
  f.np = m.np;
  f.windows_accepted = m.windows_accepted;
  f.windows_total = m.windows_total;
  f.fs = m.fs;
  f.duration = m.duration;
  if (m.bubble_count_rate > 0.0) f.chord_time = m.void_fraction / m.bubble_count_rate;
  if (m.weighting) f.awcc_unweighted = *m.weighting == awcc::Weighting::none ? 1 : 0;
  if (m.time_scale_ratio && *m.time_scale_ratio > 0.0) f.time_scale_ratio = *m.time_scale_ratio;
  auto d32_of = [&](double u) {
    return m.bubble_count_rate > 0.0 ? 1.5 * u * m.void_fraction / m.bubble_count_rate : m.d32.value_or(0.0);
  };
  if (m.fscc_velocity && *m.fscc_velocity > 0.0) {
    f.fscc_velocity = *m.fscc_velocity;
    f.r12_max = m.r12_max.value_or(0.0);
    f.tu_chanson = m.tu_chanson;
    f.fscc_d32 = d32_of(f.fscc_velocity);
  }
  if (!m.velocity || !m.turbulence_intensity) {
    r.status = CorrectionStatus::no_awcc_velocity;
    r.message = "AWCC gave no velocity";
    return r;
  }
  if (!(*m.velocity > 0.0)) {
    // The velocity target is the ratio true / measured: a measured velocity
    // that is not positive has no correction.
    r.status = CorrectionStatus::no_awcc_velocity;
    r.message = fmt::format("AWCC's velocity {:.6g} m/s is not positive", *m.velocity);
    return r;
  }
  if (!(m.bubble_count_rate > 0.0) && !(m.d32 && *m.d32 > 0.0)) {
    r.status = CorrectionStatus::no_bubbles;
    r.message = "no bubbles on the leading tip";
    return r;
  }
  f.velocity = *m.velocity;
  f.turbulence_intensity = *m.turbulence_intensity;
  f.d32 = d32_of(f.velocity);
  return r;
}

std::string fscc_unusable(const Features& f) {
  if (!(f.fscc_velocity > 0.0)) return "FSCC gave no velocity";
  if (!(f.fscc_d32 > 0.0)) return "no bubbles on the leading tip";
  return {};
}

std::optional<double> Features::value(std::string_view name) const {
  const auto measured = vector();
  for (std::size_t j = 0; j < names.size(); ++j)
    if (name == names[j]) return measured[j];
  if (name == "fs" && fs > 0.0) return fs;
  if (name == "duration" && duration > 0.0) return duration;
  if (name == "windows_accepted" && windows_accepted >= 0) return static_cast<double>(windows_accepted);
  if (name == "data_yield" && windows_accepted >= 0 && windows_total > 0) {
    return static_cast<double>(windows_accepted) / static_cast<double>(windows_total);
  }
  if (name == "fscc_velocity" && fscc_velocity > 0.0) return fscc_velocity;
  if (name == "r12_max" && fscc_velocity > 0.0) return r12_max;
  if (name == "fscc_d32" && fscc_d32 > 0.0) return fscc_d32;
  if (name == "chord_time" && chord_time > 0.0) return chord_time;
  if (name == weighting_name && awcc_unweighted >= 0) return static_cast<double>(awcc_unweighted);
  if (name == "fscc_lag" && fscc_velocity > 0.0) return dx / fscc_velocity;
  if (name == lag_name && fs > 0.0 && velocity > 0.0) return dx * fs / velocity;
  if (name == scale_name && time_scale_ratio > 0.0) return time_scale_ratio;
  if (name == size_name && d32 > 0.0 && dx > 0.0) return d32 / dx;
  if (name == fscc_ratio_name && fscc_velocity > 0.0 && velocity > 0.0) return fscc_velocity / velocity;
  if (name == chanson_name && fscc_velocity > 0.0) return tu_chanson;
  return std::nullopt;
}

bool Features::on_log_scale(std::string_view name) {
  return std::find(log_scale_names.begin(), log_scale_names.end(), name) != log_scale_names.end();
}

std::vector<std::string> feature_set_names(std::string_view set) {
  if (set == "fscc") return {Features::fscc_names.begin(), Features::fscc_names.end()};
  if (set == "fscc-2") return {Features::fscc2_names.begin(), Features::fscc2_names.end()};
  auto bad = [&] {
    return std::invalid_argument(fmt::format(
        "feature set '{}': use measured (the seven of METHOD 7), extended (with fs, duration and accepted windows) "
        "or extended-yield (fs, duration and the data yield), the extended two optionally followed by +lag (the lag "
        "in samples), then +scale (the time-scale ratio T_u / T_W), then +size (d32 / dx), then +fscc (FSCC's "
        "velocity over AWCC's and FSCC's R12max), then +chanson (FSCC's Chanson Tu), each then optionally by "
        "+weighting",
        set));
  };
  const auto plus = set.find('+');
  const std::string_view base = set.substr(0, plus);
  std::string_view rest = plus == std::string_view::npos ? std::string_view() : set.substr(plus);
  if (base != "measured" && base != "extended" && base != "extended-yield") throw bad();
  std::vector<std::string> out(Features::names.begin(), Features::names.end());
  if (base != "measured") out.insert(out.end(), Features::record_names.begin(), Features::record_names.end());
  if (base == "extended-yield") out.back() = "data_yield";
  // The suffixes, each at most once and in this order.
  auto take = [&](std::string_view suffix) {
    if (!rest.starts_with(suffix) || (rest.size() > suffix.size() && rest[suffix.size()] != '+')) return false;
    rest.remove_prefix(suffix.size());
    return true;
  };
  using Names = std::vector<const char*>;
  for (const auto& [suffix, names, extended_only] :
       {std::tuple{"+lag", Names{Features::lag_name}, true}, std::tuple{"+scale", Names{Features::scale_name}, true},
        std::tuple{"+size", Names{Features::size_name}, true},
        std::tuple{"+fscc", Names{Features::fscc_ratio_name, "r12_max"}, true},
        std::tuple{"+chanson", Names{Features::chanson_name}, true},
        std::tuple{"+weighting", Names{Features::weighting_name}, false}}) {
    if (!take(suffix)) continue;
    if (extended_only && base == "measured") throw bad();
    out.insert(out.end(), names.begin(), names.end());
  }
  if (!rest.empty()) throw bad();
  return out;
}

std::string feature_set_of(const std::vector<std::string>& names) {
  for (const char* base : {"measured", "extended", "extended-yield"}) {
    for (const char* lag : {"", "+lag"}) {
      for (const char* scale : {"", "+scale"}) {
        for (const char* size : {"", "+size"}) {
          for (const char* fscc : {"", "+fscc"}) {
            for (const char* chanson : {"", "+chanson"}) {
              for (const char* weighting : {"", "+weighting"}) {
                std::string set = std::string(base) + lag + scale + size + fscc + chanson + weighting;
                if (std::string_view(base) == "measured" && (*lag || *scale || *size || *fscc || *chanson)) continue;
                if (names == feature_set_names(set)) return set;
              }
            }
          }
        }
      }
    }
  }
  return {};
}

MeasurementResult measurement_of(const awcc::ProcessResult& r) {
  MeasurementResult out;
  // What every forest shares and FSCC's own, whatever AWCC gave.
  auto& m = out.measurement;
  if (!r.tips.empty()) {
    m.void_fraction = r.tips[0].phase.void_fraction;
    m.bubble_count_rate = r.tips[0].phase.bubble_count_rate;
  }
  m.dx = r.dx;
  m.dy = r.dy;
  m.fs = r.info.fs;
  m.duration = r.info.fs > 0.0 ? static_cast<double>(r.info.frames) / r.info.fs : 0.0;
  if (r.fscc && r.fscc->ok()) {
    m.fscc_velocity = r.fscc->velocity;
    m.r12_max = r.fscc->r12_max;
    m.tu_chanson = r.fscc->turbulence_intensity_chanson.value_or(0.0);
  }
  if (r.awcc) {
    m.np = r.awcc->np;
    m.weighting = r.awcc->weighting;
    m.windows_accepted = r.awcc->windows_accepted;
    m.windows_total = r.awcc->windows_total;
  }
  if (!r.awcc) {
    out.status = CorrectionStatus::awcc_not_run;
    out.message = "AWCC was not run";
  } else if (!r.awcc->ok()) {
    out.status = CorrectionStatus::no_awcc_velocity;
    out.message = "AWCC gave no velocity: " + r.awcc->message;
  } else if (r.awcc->probe_corrected) {
    // The model learnt AWCC's bias on synthetic records without the needle:
    // a bubble-probe-corrected velocity is not what it corrects.
    out.status = CorrectionStatus::probe_corrected;
    out.message = "AWCC's velocity is bubble-probe corrected: the model corrects the uncorrected AWCC; process "
                  "without the probe correction to correct it";
  } else {
    m.velocity = r.awcc->velocity;
    m.turbulence_intensity = r.awcc->turbulence_intensity;
    m.time_scale_ratio = r.awcc->time_scale_ratio;
    // AWCC's edge and spread rules: the model learnt AWCC's bias where its
    // lags were measured; a study still records the raw values above.
    if (!r.awcc->turbulence_measured || awcc::lags_pile_up_at_range_end(*r.awcc)) {
      out.status = CorrectionStatus::awcc_not_measured;
      out.message = "AWCC's lags are not measured: " + r.awcc->quality_reason;
    }
  }
  return out;
}

Processing processing_of(const awcc::AwccOptions& o) {
  return {o.filter_a, o.roc, o.weighting, o.signal, o.subsample};
}

std::string describe(const Processing& p) {
  return fmt::format("filter A {:g}, robust outlier cutoff {}, {} weighting, {} signals, peak refinement {}", p.filter_a,
                     p.roc ? "on" : "off", awcc::to_string(p.weighting), awcc::to_string(p.signal),
                     awcc::to_string(p.subsample));
}

std::string processing_mismatch(const Processing& model, const Processing& results) {
  std::string out;
  auto add = [&](const char* what, const std::string& a, const std::string& b) {
    if (a == b) return;
    out += fmt::format("{}{}: model {}, results {}", out.empty() ? "" : "; ", what, a, b);
  };
  add("filter A", fmt::format("{:g}", model.filter_a), fmt::format("{:g}", results.filter_a));
  add("robust outlier cutoff", model.roc ? "on" : "off", results.roc ? "on" : "off");
  add("weighting", std::string(awcc::to_string(model.weighting)), std::string(awcc::to_string(results.weighting)));
  add("correlated signal", std::string(awcc::to_string(model.signal)), std::string(awcc::to_string(results.signal)));
  add("peak refinement", std::string(awcc::to_string(model.subsample)), std::string(awcc::to_string(results.subsample)));
  return out;
}

}  // namespace correction
