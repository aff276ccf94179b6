// The error study over a multi-tip probe's geometry (issue 30; the figure
// docs/figures/multi-tip-geometry.png, docs/validation.md "Tip geometry"):
//
//   multi_tip_geometry docs/studies/multi-tip-geometry.toml OUT.csv
//
// The definition is a sweep file (study/sweep.hpp: [sweep], [base], [grid];
// the tips as a grid of `tips` strings, anisotropy as Tu_y/Tu_x). Each run is
// validated bubble by bubble (study/multi_tip_validate.hpp): pdp process's
// processing of the probe, both velocity algorithms on its pairing with
// pdp's quality of each, event detection, FSCC and AWCC on the dual tip,
// every estimate against the realised truth. One CSV row a run; bias and
// spread over the seeds are the figure script's (scripts/multi-tip-geometry).
// One thread: the study is sized to run in about a minute on one core, so it
// is not resumable.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "awcc/multi_tip.hpp"
#include "study/multi_tip_validate.hpp"
#include "study/sweep.hpp"

namespace {

std::string num(const std::optional<double>& x) { return x && std::isfinite(*x) ? fmt::format("{:.6g}", *x) : ""; }
std::string num(double x) { return std::isfinite(x) ? fmt::format("{:.6g}", x) : ""; }

// The streamwise spacing of the trailing tips and their largest lateral
// offset from the leading tip: the two lengths the study's geometry scales.
std::pair<double, double> spacing_of(const awcc::ProbeGeometry& g) {
  double streamwise = 0.0, lateral = 0.0;
  const auto& lead = g.positions()[g.leading()];
  for (const auto k : g.trailing_tips()) {
    const auto& p = g.positions()[k];
    streamwise = std::max(streamwise, p[0] - lead[0]);
    lateral = std::max(lateral, std::hypot(p[1] - lead[1], p[2] - lead[2]));
  }
  return {streamwise, lateral};
}

const char* kHeader =
    "index,seed,velocity,bubble_diameter,void_fraction,tu,tu_y,tu_z,anisotropy,spacing,lateral,spacing_ratio,"
    "conditioning,leading_bubbles,pairing_error,pairing_yield,"
    "sn_status,sn_quality,sn_quality_reason,sn_accepted,sn_mispaired,sn_mispaired_weight,sn_selected_ux,sn_ux,sn_uy,"
    "sn_uz,sn_tux,sn_tuy,sn_tuz,sn_iac,sn_iac_realised,sn_iac_paired,sn_speed_median,sn_speed_p90,sn_vector_median,"
    "sn_diameter_median,"
    "tian_status,tian_quality,tian_quality_reason,tian_accepted,tian_ux,tian_uy,tian_uz,tian_tux,tian_tuy,tian_tuz,"
    "tian_speed_median,tian_speed_p90,tian_vector_median,sn_tian_max_difference,"
    "ed_status,ed_paired,ed_pairing_error,ed_u,ed_tu,ed_velocity_median,awcc_quality,awcc_u,awcc_tu,fscc_u,"
    "seconds_synth,seconds_process,error\n";

// A free text as one CSV field: the separators and quotes blanked.
std::string field(std::string text) {
  for (auto& c : text)
    if (c == '"' || c == '\n' || c == ',') c = ' ';
  return text;
}

std::string row(const study::SweepRun& run, const study::MultiTipValidation* v, const std::string& error) {
  const auto& s = run.scene;
  std::string out = fmt::format("{},{},{},{},{},{},{},{},{},", run.index, s.seed, s.velocity, s.bubble_diameter,
                                s.void_fraction, s.tu, s.tu_y, s.tu_z, run.anisotropy);
  if (!v) {
    // The run's own columns, then every result column empty, then the reason.
    const std::string header(kHeader);
    const auto empty = std::count(header.begin(), header.end(), ',') - 9;
    for (std::ptrdiff_t i = 0; i < empty; ++i) out += ',';
    return out + field(error) + "\n";
  }
  const auto [spacing, lateral] = spacing_of(v->geometry);
  out += fmt::format("{},{},{},{},{},{},{},", num(spacing), num(lateral), num(spacing / s.bubble_diameter),
                     num(v->conditioning), v->leading_bubbles, num(v->pairing_total.error_fraction()),
                     num(v->pairing_total.yield()));
  const study::VectorValidation* sn = nullptr;
  const study::VectorValidation* tian = nullptr;
  for (const auto& a : v->algorithms) {
    if (a.result.options.algorithm == awcc::VelocityAlgorithm::shen_nakamura) sn = &a;
    if (a.result.options.algorithm == awcc::VelocityAlgorithm::tian) tian = &a;
  }
  auto algorithm = [&](const study::VectorValidation* a, bool sn_columns) {
    std::string o;
    if (!a) return std::string(sn_columns ? 20 : 13, ',');
    // pdp's verdict: a large error with quality ok is the one a user cannot see.
    o += fmt::format("{},{},{},{},", awcc::to_string(a->result.status), awcc::to_string(a->quality),
                     a->quality == awcc::AwccQuality::ok ? std::string() : field(a->quality_reason),
                     a->result.bubbles_accepted);
    if (sn_columns) {
      o += fmt::format("{},{},{},", a->accepted_mispaired, num(a->mispaired_weight_share),
                       num(a->selected_velocity[0].error()));
    }
    for (const auto& c : a->mean_velocity) o += num(c.error()) + ",";
    for (const auto& c : a->turbulence_intensity) o += num(c.error()) + ",";
    if (sn_columns) {
      o += num(a->interfacial_area.error()) + "," + num(a->interfacial_area_realised.error()) + "," +
           num(a->interfacial_area_paired.error()) + ",";
    }
    auto q = [](const awcc::Summary& x, bool p90) {
      return x.count ? num(p90 ? x.percentiles[5] : x.median) : std::string();
    };
    o += q(a->speed_error, false) + "," + q(a->speed_error, true) + "," + q(a->vector_error, false) + ",";
    if (sn_columns) o += q(a->diameter_error, false) + ",";
    return o;
  };
  out += algorithm(sn, true);
  out += algorithm(tian, false);
  // The two algorithms solve one linear system (awcc/multi_tip.hpp): their
  // per-bubble vectors agree to rounding; the largest difference shows it.
  double difference = std::nan("");
  if (sn && tian && sn->result.bubbles.size() == tian->result.bubbles.size()) {
    difference = 0.0;
    for (std::size_t h = 0; h < sn->result.bubbles.size(); ++h) {
      const auto& a = sn->result.bubbles[h];
      const auto& b = tian->result.bubbles[h];
      if (a.fate != awcc::VectorFate::solved || b.fate != awcc::VectorFate::solved) continue;
      for (std::size_t i = 0; i < 3; ++i) {
        difference = std::max(difference, std::fabs(a.velocity[i] - b.velocity[i]) / s.velocity);
      }
    }
  }
  out += num(difference) + ",";
  const auto& d = v->dual;
  out += fmt::format("{},{},{},{},{},{},", awcc::to_string(d.events.status), d.events.bubbles_paired,
                     num(d.pairing.error_fraction()), num(d.ed_velocity.error()),
                     num(d.ed_turbulence_intensity.error()),
                     d.velocity_error.count ? num(d.velocity_error.median) : std::string());
  out += fmt::format("{},{},{},", d.processed.awcc ? std::string(awcc::to_string(d.processed.awcc->quality)) : "",
                     num(d.awcc_velocity.error()), num(d.awcc_turbulence_intensity.error()));
  // FSCC's velocity of the pair against the realised u_x: the reference the
  // probe's quality compares the mean vector with (ProbeResult::quality).
  const auto& f = d.processed.fscc;
  const double ux = v->realised_velocity[0];
  out += (f && f->ok() ? num((f->velocity - ux) / ux) : std::string()) + ",";
  out += fmt::format("{:.3f},{:.3f},\n", v->seconds_synth, v->seconds_process);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: multi_tip_geometry DEFINITION.toml OUT.csv\n");
    return 2;
  }
  try {
    const auto definition = study::load_sweep(argv[1]);
    const auto runs = definition.expand();
    std::ofstream csv(argv[2]);
    if (!csv) throw std::runtime_error(fmt::format("{}: cannot be written", argv[2]));
    csv << kHeader;
    study::MultiTipValidateOptions options;
    options.dual.window_truth = false;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      std::string line;
      try {
        const auto v = study::validate_multi_tip(runs[i].scene, options);
        line = row(runs[i], &v, "");
      } catch (const std::exception& e) {
        line = row(runs[i], nullptr, e.what());
      }
      csv << line << std::flush;
      std::fprintf(stderr, "\r%zu of %zu runs", i + 1, runs.size());
    }
    std::fprintf(stderr, "\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "multi_tip_geometry: %s\n", e.what());
    return 1;
  }
  return 0;
}
