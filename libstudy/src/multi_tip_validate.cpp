#include "study/multi_tip_validate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fmt/format.h>
#include <functional>
#include <limits>
#include <stdexcept>

#include "awcc/interface_times.hpp"
#include "awcc/random.hpp"
#include "study/clock.hpp"
#include "synth/synthesiser.hpp"

namespace study {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double norm(const awcc::Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

}  // namespace

std::vector<std::optional<std::size_t>> match_truth_rows(const synth::BubbleTruth& truth, std::size_t tip,
                                                         std::span<const awcc::Crossing> crossings, double tolerance) {
  if (tip >= truth.tip_count) {
    throw std::invalid_argument(fmt::format("match_truth_rows: tip {} of a truth table of {} tips", tip, truth.tip_count));
  }
  // The rows that pierced the tip, by their front there.
  std::vector<std::pair<double, std::size_t>> fronts;
  fronts.reserve(truth.size());
  for (std::size_t r = 0; r < truth.size(); ++r) {
    const auto& p = truth.pierce(r, tip);
    if (p.pierced()) fronts.emplace_back(p.front, r);
  }
  std::sort(fronts.begin(), fronts.end());
  std::vector<std::optional<std::size_t>> rows(crossings.size());
  for (std::size_t i = 0; i < crossings.size(); ++i) {
    const double t = crossings[i].front;
    auto it = std::lower_bound(fronts.begin(), fronts.end(), std::pair{t, std::size_t{0}});
    double gap = tolerance;
    // The closest front is the first at or after t or the last before it.
    for (auto c : {it, it == fronts.begin() ? fronts.end() : std::prev(it)}) {
      if (c == fronts.end()) continue;
      const double d = std::fabs(c->first - t);
      if (d <= gap) {
        gap = d;
        rows[i] = c->second;
      }
    }
  }
  return rows;
}

double PartnerScore::error_fraction() const {
  return partners > 0 ? static_cast<double>(wrong) / static_cast<double>(partners) : kNaN;
}

double PartnerScore::yield() const {
  return truth_pairs > 0 ? static_cast<double>(found) / static_cast<double>(truth_pairs) : kNaN;
}

PartnerScore& PartnerScore::operator+=(const PartnerScore& other) {
  partners += other.partners;
  wrong += other.wrong;
  truth_pairs += other.truth_pairs;
  found += other.found;
  return *this;
}

PartnerScore score_partners(const synth::BubbleTruth& truth, std::span<const std::optional<std::size_t>> rows,
                            std::size_t tip, std::span<const std::optional<double>> partner_fronts, double tolerance) {
  if (rows.size() != partner_fronts.size()) {
    throw std::invalid_argument(fmt::format("score_partners: {} truth rows for {} leading bubbles", rows.size(),
                                            partner_fronts.size()));
  }
  if (tip >= truth.tip_count) {
    throw std::invalid_argument(fmt::format("score_partners: tip {} of a truth table of {} tips", tip, truth.tip_count));
  }
  PartnerScore s;
  for (std::size_t h = 0; h < rows.size(); ++h) {
    const synth::TipPierce* at_tip = rows[h] ? &truth.pierce(*rows[h], tip) : nullptr;
    const bool to_find = at_tip && at_tip->pierced();
    const auto& partner = partner_fronts[h];
    const bool right = to_find && partner && std::fabs(at_tip->front - *partner) <= tolerance;
    s.truth_pairs += to_find ? 1 : 0;
    s.found += right ? 1 : 0;
    if (partner) {
      ++s.partners;
      s.wrong += right ? 0 : 1;
    }
  }
  return s;
}

std::optional<double> Compared::error() const {
  if (!value || !(scale != 0.0) || !std::isfinite(*value)) return std::nullopt;
  return (*value - truth) / scale;
}

namespace {

// The probe as pdp process takes it from a user: every tip declared (tip k
// on channel k), the leading tip the most upstream one, multi-tip
// processing and event detection on.
awcc::ProcessOptions probe_options(const awcc::ProbeGeometry& geometry, const MultiTipValidateOptions& options) {
  awcc::ProcessOptions p = processing_options(options.dual, 0.0, 0.0);
  for (const auto& t : geometry.positions()) p.probe.positions.push_back(t);
  p.probe.leading = static_cast<int>(geometry.leading());
  p.events = true;
  p.event_options = options.events;
  p.multi_tip = awcc::MultiTipChoice::on;
  p.multi_tip_options = options.multi_tip;
  return p;
}

awcc::RecordingInfo synthetic_info(const synth::Scene& scene, std::size_t tips) {
  awcc::RecordingInfo info;
  info.description = "synthesised binary signals";
  info.channels = static_cast<int>(tips);
  info.fs = scene.fs;
  info.frames = static_cast<std::int64_t>(std::llround(scene.duration * scene.fs));
  info.quantum = 1.0;
  return info;
}

// The synthetic signals as process_binarised takes a probe's recording
// (awcc::binary_recording, the signal check included): the tip pair first,
// then the further tips, in the channel order pdp process chose
// (`resolved`, from tip_pair_options), with every tip's position.
awcc::BinarisedRecording probe_recording(const synth::Synthesis& syn, const awcc::ProcessOptions& resolved,
                                         const awcc::ProbeGeometry& geometry) {
  const auto channels = resolved.tip_channels();
  std::vector<awcc::AirIntervals> signals;
  std::vector<awcc::Vec3> positions;
  for (const int c : channels) {
    signals.push_back(syn.signals.at(static_cast<std::size_t>(c)));
    positions.push_back(geometry.positions().at(static_cast<std::size_t>(c)));
  }
  auto r = awcc::binary_recording(std::move(signals), resolved, channels, std::move(positions));
  r.info.channels = static_cast<int>(syn.signals.size());
  return r;
}

// What the scene's processing gave: pdp process's result of the first
// algorithm (FSCC, AWCC and event detection of the tip pair, the probe) and
// each algorithm's probe result. The one place the processing is called.
struct Processed {
  awcc::ProcessResult result;
  std::vector<awcc::ProbeResult> probes;  ///< in the options' order of algorithms
};

Processed process_probe(const awcc::BinarisedRecording& recording, const awcc::ProcessOptions& given,
                        const MultiTipValidateOptions& options) {
  Processed out;
  for (const auto algorithm : options.algorithms) {
    auto o = given;
    o.multi_tip_options.algorithm = algorithm;
    o.events = out.probes.empty();  // one event detection: it does not depend on the algorithm
    auto r = awcc::process_binarised(recording, o);
    if (!r.probe) throw std::logic_error("validate_multi_tip: process_binarised gave no multi-tip result");
    out.probes.push_back(*r.probe);
    if (out.probes.size() == 1) out.result = std::move(r);
  }
  return out;
}

awcc::Vec3 to_vec(const synth::Vec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

MultiTipValidation validate_multi_tip(const synth::Scene& scene, const MultiTipValidateOptions& options) {
  MultiTipValidation v;
  v.scene = scene;
  const auto tips = scene.probe_tips();
  if (tips.size() < 4) {
    throw std::invalid_argument(
        fmt::format("tips: the scene has {} tips; a multi-tip validation needs 4 or more (a leading tip and three "
                    "trailing tips not in one plane with it)",
                    tips.size()));
  }
  std::vector<awcc::Vec3> positions;
  for (const auto& t : tips) positions.push_back(to_vec(t));
  v.geometry = awcc::ProbeGeometry(positions);
  if (const auto check = v.geometry.check(options.multi_tip.conditioning_min); !check.ok()) {
    throw awcc::OptionError(check.message, check.quantity);
  }
  for (const auto& c : v.geometry.combinations()) v.conditioning = std::max(v.conditioning, c.conditioning());

  // The tip pair and the further tips' order: pdp process's choice
  // (tip_pair_options: the leading tip and the first tip after it, in the
  // tips' order, downstream of it), made before the synthesis so that a
  // probe pdp refuses costs nothing.
  const auto given = probe_options(v.geometry, options);
  const auto resolved = awcc::tip_pair_options(given, synthetic_info(scene, tips.size()));
  const auto channels = resolved.tip_channels();
  auto& d = v.dual;
  d.leading_tip = static_cast<std::size_t>(channels.at(0));
  d.trailing_tip = static_cast<std::size_t>(channels.at(1));
  d.dx = resolved.dx;
  d.dy = resolved.dy;
  if (d.leading_tip != v.geometry.leading() || channels.size() != tips.size()) {
    throw std::logic_error("validate_multi_tip: pdp process chose another leading tip or dropped a tip");
  }

  synth::SynthesisOptions so;
  so.bubble_truth = true;
  auto start = std::chrono::steady_clock::now();
  const auto syn = synth::synthesise(scene, so);
  v.seconds_synth = seconds_since(start);
  const auto& truth = syn.truth;
  const auto& table = *syn.bubbles;
  v.realised_velocity = truth.realised.mean_velocity;
  v.realised_turbulence_intensity = truth.realised.turbulence_intensity;
  v.expected_interfacial_area = truth.expected_interfacial_area;
  v.realised_interfacial_area = truth.tips.at(d.leading_tip).interfacial_area;
  v.truth_bubbles = static_cast<std::int64_t>(table.size());
  const double realised_speed = norm(v.realised_velocity);

  start = std::chrono::steady_clock::now();
  auto processed = process_probe(probe_recording(syn, resolved, v.geometry), given, options);
  v.seconds_process = seconds_since(start);

  const double tolerance = options.match_tolerance_samples / syn.signals.at(d.leading_tip).fs;
  const auto& probe = processed.probes.front();
  if (probe.channels != channels) {
    throw std::logic_error("validate_multi_tip: process_binarised ordered the tips otherwise than tip_pair_options");
  }
  const auto& pairing = probe.pairing;
  v.pairing_status = pairing.status;
  v.pairing_message = pairing.message;
  // The processing's trailing tips are its tips 1, 2, ... (channels[1],
  // channels[2], ...); the study's are the scene's tips in their order.
  // processed_at[k]: the processing's position of the study's trailing tip k.
  const auto& trailing = v.geometry.trailing_tips();
  std::vector<std::size_t> processed_at(trailing.size());
  for (std::size_t k = 0; k < trailing.size(); ++k) {
    const auto it = std::find(channels.begin() + 1, channels.end(), static_cast<int>(trailing[k]));
    processed_at[k] = static_cast<std::size_t>(it - channels.begin()) - 1;
  }
  for (std::size_t k = 0; k < trailing.size() && pairing.fates.size() == trailing.size(); ++k) {
    v.pairing_fates.push_back(pairing.fates[processed_at[k]]);
  }
  const auto& leading = pairing.bubbles.leading;
  // Without a pairing (Shen's without a first velocity) there are no
  // bubbles to score; the leading tip's crossings still count.
  const auto lead_crossings = awcc::crossings(syn.signals.at(d.leading_tip));
  const auto rows = match_truth_rows(table, d.leading_tip, lead_crossings, tolerance);
  v.leading_bubbles = static_cast<std::int64_t>(rows.size());
  v.leading_matched = std::count_if(rows.begin(), rows.end(), [](const auto& r) { return r.has_value(); });

  // The probe's pairing holds every leading crossing in order (pair_probe):
  // the rows of its leading bubbles are the crossings' rows.
  // A leading bubble with a wrong partner at any trailing tip (score_partners' rule).
  std::vector<bool> mispaired(leading.size(), false);
  if (pairing.ok()) {
    if (leading.size() != lead_crossings.size()) {
      throw std::logic_error("validate_multi_tip: the pairing's leading bubbles are not the leading tip's crossings");
    }
    std::vector<std::optional<double>> fronts(leading.size());
    for (std::size_t k = 0; k < trailing.size(); ++k) {
      for (std::size_t h = 0; h < leading.size(); ++h) {
        const auto& p = pairing.bubbles.partner(h, processed_at[k]);
        fronts[h] = p ? std::optional(p->front) : std::nullopt;
        if (!p) continue;
        const auto* at_tip = rows[h] ? &table.pierce(*rows[h], trailing[k]) : nullptr;
        if (!at_tip || !at_tip->pierced() || std::fabs(at_tip->front - p->front) > tolerance) mispaired[h] = true;
      }
      v.pairing.push_back(score_partners(table, rows, trailing[k], fronts, tolerance));
      v.pairing_total += v.pairing.back();
    }
  }

  for (auto& processed_probe : processed.probes) {
    auto& result = processed_probe.vectors;
    VectorValidation a;
    a.quality = processed_probe.quality;
    a.quality_reason = processed_probe.quality_reason;
    std::vector<double> speed, vector, diameter;
    awcc::Vec3 selected{};
    double selected_weight = 0.0, weight = 0.0, mispaired_weight = 0.0;
    for (std::size_t h = 0; h < result.bubbles.size(); ++h) {
      const auto& b = result.bubbles[h];
      if (b.fate != awcc::VectorFate::solved) continue;
      weight += b.weight;
      if (h < mispaired.size() && (mispaired[h] || !rows[h])) {
        ++a.accepted_mispaired;
        mispaired_weight += b.weight;
      }
      if (!rows[h]) continue;
      const auto truth_v = to_vec(table.velocity[*rows[h]]);
      for (std::size_t i = 0; i < 3; ++i) selected[i] += b.weight * truth_v[i];
      selected_weight += b.weight;
      const double true_speed = norm(truth_v);
      if (!(true_speed > 0.0)) continue;
      speed.push_back(std::fabs(norm(b.velocity) - true_speed) / true_speed);
      vector.push_back(norm({b.velocity[0] - truth_v[0], b.velocity[1] - truth_v[1], b.velocity[2] - truth_v[2]}) /
                       true_speed);
      if (std::isfinite(b.diameter_front)) {
        const double true_d = table.diameter[*rows[h]];
        diameter.push_back(std::fabs(b.diameter_front - true_d) / true_d);
      }
    }
    a.mispaired_weight_share = weight > 0.0 ? mispaired_weight / weight : kNaN;
    a.speed_error = awcc::summarise(std::move(speed));
    a.vector_error = awcc::summarise(std::move(vector));
    a.diameter_error = awcc::summarise(std::move(diameter));
    for (std::size_t i = 0; i < 3; ++i) {
      a.mean_velocity[i] = {result.ok() ? std::optional(result.velocity[i]) : std::nullopt, v.realised_velocity[i],
                            realised_speed};
      a.selected_velocity[i] = {result.ok() && selected_weight > 0.0
                                    ? std::optional(selected[i] / selected_weight)
                                    : std::nullopt,
                                v.realised_velocity[i], realised_speed};
      a.turbulence_intensity[i] = {result.ok() ? std::optional(result.turbulence_intensity[i]) : std::nullopt,
                                   v.realised_turbulence_intensity[i], v.realised_turbulence_intensity[i]};
    }
    a.interfacial_area = {result.interfacial_area, v.expected_interfacial_area, v.expected_interfacial_area};
    a.interfacial_area_realised = {result.interfacial_area, v.realised_interfacial_area.value_or(0.0),
                                   v.realised_interfacial_area.value_or(0.0)};
    a.interfacial_area_paired = {result.interfacial_area_paired, v.expected_interfacial_area,
                                 v.expected_interfacial_area};
    a.result = std::move(result);
    v.algorithms.push_back(std::move(a));
  }

  // The dual tip: ED's partners and per-bubble velocities against the truth,
  // ED's and AWCC's moments against the realised streamwise ones.
  if (!processed.result.events) throw std::logic_error("validate_multi_tip: process_binarised ran no event detection");
  d.events = *processed.result.events;
  d.processed = std::move(processed.result);
  {
    const auto& ed = d.events.bubbles;
    const auto ed_rows = ed.size() == lead_crossings.size() ? rows : std::vector<std::optional<std::size_t>>(ed.size());
    std::vector<std::optional<double>> fronts(ed.size());
    std::vector<double> errors;
    for (std::size_t h = 0; h < ed.size(); ++h) {
      // The pairing's partners are the paired bubbles and those the outlier
      // cutoff removed after pairing (the probe's pairing has no cutoff);
      // the velocities are of the paired ones.
      if (ed[h].fate == awcc::BubbleFate::paired || ed[h].fate == awcc::BubbleFate::roc) {
        fronts[h] = ed[h].trailing_front;
      }
      if (ed[h].fate != awcc::BubbleFate::paired || !ed_rows[h]) continue;
      const double vx = table.velocity[*ed_rows[h]].x;
      if (vx != 0.0) errors.push_back(std::fabs(ed[h].velocity - vx) / std::fabs(vx));
    }
    if (!ed.empty()) d.pairing = score_partners(table, ed_rows, d.trailing_tip, fronts, tolerance);
    d.velocity_error = awcc::summarise(std::move(errors));
  }
  const double ux = v.realised_velocity[0], tux = v.realised_turbulence_intensity[0];
  const bool ed_ok = d.events.ok();
  d.ed_velocity = {ed_ok ? std::optional(d.events.velocity) : std::nullopt, ux, ux};
  d.ed_turbulence_intensity = {ed_ok ? std::optional(d.events.turbulence_intensity) : std::nullopt, tux, tux};
  const auto& aw = d.processed.awcc;
  const bool awcc_ok = aw && aw->ok();
  d.awcc_velocity = {awcc_ok ? std::optional(aw->velocity) : std::nullopt, ux, ux};
  d.awcc_turbulence_intensity = {awcc_ok ? std::optional(aw->turbulence_intensity) : std::nullopt, tux, tux};
  return v;
}

namespace {

std::string pct(const std::optional<double>& e) {
  return e ? fmt::format("{:+.2f} %", 100.0 * *e) : std::string("n/a");
}

std::string val(const std::optional<double>& x, double scale = 1.0, const char* f = "{:.4f}") {
  return x ? fmt::format(fmt::runtime(f), *x * scale) : std::string("n/a");
}

std::string quantiles(const awcc::Summary& s) {
  // Summary::percentiles holds the 5, 10, 25, 50, 75, 90 and 95th.
  if (s.count == 0) return "n/a";
  return fmt::format("median {:.2f} %, 90th percentile {:.2f} % ({} bubbles)", 100.0 * s.median,
                     100.0 * s.percentiles[5], s.count);
}

std::string partner_line(const PartnerScore& s) {
  return fmt::format("{} partners, {} wrong ({:.3f} %); found {} of the {} the truth holds (yield {:.1f} %)",
                     s.partners, s.wrong, 100.0 * s.error_fraction(), s.found, s.truth_pairs, 100.0 * s.yield());
}

void compared_row(std::string& out, const std::string& name, const Compared& c, double scale = 1.0,
                  const char* f = "{:.4f}") {
  out += fmt::format("  {:<30}{:>12}{:>12}{:>12}\n", name, fmt::format(fmt::runtime(f), c.truth * scale),
                     val(c.value, scale, f), pct(c.error()));
}

}  // namespace

std::string multi_tip_report(const MultiTipValidation& v) {
  std::string out;
  const auto& g = v.geometry;
  out += fmt::format("probe: {} tips, leading {}; best combination's conditioning |det A_0| = {:.3f}\n",
                     g.tip_count(), g.tip_name(g.leading()), v.conditioning);
  out += fmt::format("truth: {} bubbles pierced a tip; {} leading bubbles, {} matched to their truth row\n",
                     v.truth_bubbles, v.leading_bubbles, v.leading_matched);
  out += fmt::format("pairing (leading tip with each trailing tip, {}):\n",
                     v.pairing_status == awcc::EventStatus::ok ? std::string("against the truth")
                                                               : "refused: " + v.pairing_message);
  for (std::size_t k = 0; k < v.pairing.size(); ++k) {
    out += fmt::format("  {}: {}\n", g.tip_name(g.trailing_tips()[k]), partner_line(v.pairing[k]));
  }
  if (!v.pairing.empty()) out += fmt::format("  all: {}\n", partner_line(v.pairing_total));
  for (const auto& a : v.algorithms) {
    const auto& r = a.result;
    out += fmt::format("{}: status {}{}\n", awcc::to_string(r.options.algorithm), awcc::to_string(r.status),
                       r.ok() ? std::string() : ": " + r.message);
    out += fmt::format("  pdp's quality: {}{}\n", awcc::to_string(a.quality),
                       a.quality == awcc::AwccQuality::ok ? std::string() : " (" + a.quality_reason + ")");
    out += fmt::format("  bubbles: {} leading, {} solved, {} censored, {} too few tips, {} ill-conditioned, {} "
                       "degenerate, {} outlier cutoff\n",
                       r.bubbles_total, r.bubbles_accepted, r.count(awcc::VectorFate::censored),
                       r.count(awcc::VectorFate::too_few_tips), r.count(awcc::VectorFate::ill_conditioned),
                       r.count(awcc::VectorFate::degenerate), r.count(awcc::VectorFate::roc));
    out += fmt::format("  accepted with a wrong partner: {} of {}, carrying {:.1f} % of the weights\n",
                       a.accepted_mispaired, r.bubbles_accepted, 100.0 * a.mispaired_weight_share);
    out += fmt::format("  per bubble: speed error {}\n", quantiles(a.speed_error));
    out += fmt::format("  per bubble: vector error |v - v_true| / |v_true| {}\n", quantiles(a.vector_error));
    if (a.diameter_error.count) out += fmt::format("  per bubble: diameter error {}\n", quantiles(a.diameter_error));
    out += fmt::format("  {:<30}{:>12}{:>12}{:>12}\n", "quantity", "truth", "estimate", "error");
    static const char* axes[] = {"x", "y", "z"};
    for (std::size_t i = 0; i < 3; ++i) {
      compared_row(out, fmt::format("mean u_{} (m/s, error / |U|)", axes[i]), a.mean_velocity[i]);
    }
    compared_row(out, "same mean of their true u_x", a.selected_velocity[0]);
    for (std::size_t i = 0; i < 3; ++i) compared_row(out, fmt::format("Tu_{}", axes[i]), a.turbulence_intensity[i]);
    if (a.interfacial_area.value) {
      compared_row(out, "IAC vs 6 c / d_b (1/m)", a.interfacial_area, 1.0, "{:.2f}");
      if (v.realised_interfacial_area) {
        compared_row(out, "IAC vs realised (1/m)", a.interfacial_area_realised, 1.0, "{:.2f}");
      }
    }
    if (a.interfacial_area_paired.value) {
      compared_row(out, "IAC of the paired (1/m)", a.interfacial_area_paired, 1.0, "{:.2f}");
    }
  }
  const auto& d = v.dual;
  out += fmt::format("dual tip: {} and {} (dx {:.3f} mm, dy {:.3f} mm)\n", g.tip_name(d.leading_tip),
                     g.tip_name(d.trailing_tip), d.dx * 1e3, d.dy * 1e3);
  out += fmt::format("  event detection: status {}{}\n", awcc::to_string(d.events.status),
                     d.events.ok() ? std::string() : ": " + d.events.message);
  out += fmt::format("  ED pairing (before its outlier cutoff, which removed {}): {}\n", d.events.count(awcc::BubbleFate::roc),
                     partner_line(d.pairing));
  out += fmt::format("  ED per bubble: |u_h - v_x| / |v_x| {}\n", quantiles(d.velocity_error));
  if (d.processed.awcc) out += "  " + awcc_status_line(*d.processed.awcc);
  out += fmt::format("  {:<30}{:>12}{:>12}{:>12}\n", "quantity", "truth", "estimate", "error");
  compared_row(out, "ED mean u_x (m/s)", d.ed_velocity);
  compared_row(out, "ED Tu_x", d.ed_turbulence_intensity);
  compared_row(out, "AWCC mean u_x (m/s)", d.awcc_velocity);
  compared_row(out, "AWCC Tu_x", d.awcc_turbulence_intensity);
  out += fmt::format("run time: synthesis {:.3f} s, processing {:.3f} s\n", v.seconds_synth, v.seconds_process);
  return out;
}

namespace {

using nlohmann::json;

json opt(const std::optional<double>& x) { return x ? json(*x) : json(nullptr); }
json finite(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json compared_json(const Compared& c) {
  return {{"value", opt(c.value)}, {"truth", c.truth}, {"error", opt(c.error())}};
}

json quantiles_json(const awcc::Summary& s) {
  if (s.count == 0) return {{"count", 0}, {"median", nullptr}, {"p90", nullptr}};
  return {{"count", s.count}, {"median", s.median}, {"p90", s.percentiles[5]}};
}

json partner_json(const PartnerScore& s) {
  return {{"partners", s.partners},
          {"wrong", s.wrong},
          {"error_fraction", finite(s.error_fraction())},
          {"truth_pairs", s.truth_pairs},
          {"found", s.found},
          {"yield", finite(s.yield())}};
}

}  // namespace

json multi_tip_to_json(const MultiTipValidation& v) {
  json out;
  const auto& g = v.geometry;
  out["seed"] = v.scene.seed;
  out["generator_version"] = awcc::generator_version;
  json tips = json::array();
  for (const auto& p : g.positions()) tips.push_back({p[0], p[1], p[2]});
  out["probe"] = {{"tips", tips}, {"leading_tip", g.leading()}, {"conditioning", v.conditioning}};
  out["truth"] = {{"velocity", v.realised_velocity},
                  {"turbulence_intensity", v.realised_turbulence_intensity},
                  {"interfacial_area_expected", v.expected_interfacial_area},
                  {"interfacial_area_realised", opt(v.realised_interfacial_area)},
                  {"bubbles", v.truth_bubbles}};
  json per_tip = json::array();
  for (std::size_t k = 0; k < v.pairing.size(); ++k) {
    json p = partner_json(v.pairing[k]);
    p["tip"] = g.trailing_tips()[k];
    if (k < v.pairing_fates.size()) {
      json fates;
      for (std::size_t f = 0; f < awcc::bubble_fate_count; ++f) fates[std::string(awcc::bubble_fate_names[f])] = v.pairing_fates[k][f];
      p["fates"] = fates;
    }
    per_tip.push_back(p);
  }
  out["pairing"] = {{"status", awcc::to_string(v.pairing_status)},
                    {"reason", v.pairing_status == awcc::EventStatus::ok ? json(nullptr) : json(v.pairing_message)},
                    {"leading_bubbles", v.leading_bubbles},
                    {"leading_matched", v.leading_matched},
                    {"tips", per_tip},
                    {"all", partner_json(v.pairing_total)}};
  json algorithms = json::object();
  for (const auto& a : v.algorithms) {
    const auto& r = a.result;
    json fates;
    for (std::size_t f = 0; f < awcc::vector_fate_count; ++f) fates[std::string(awcc::vector_fate_names[f])] = r.bubbles_by_fate[f];
    json mean = json::array(), tu = json::array(), selected = json::array();
    for (std::size_t i = 0; i < 3; ++i) {
      mean.push_back(compared_json(a.mean_velocity[i]));
      selected.push_back(compared_json(a.selected_velocity[i]));
      tu.push_back(compared_json(a.turbulence_intensity[i]));
    }
    algorithms[std::string(awcc::to_string(r.options.algorithm))] = {
        {"status", awcc::to_string(r.status)},
        {"reason", r.ok() ? json(nullptr) : json(r.message)},
        {"bubbles", r.bubbles_total},
        {"fates", fates},
        {"speed_error", quantiles_json(a.speed_error)},
        {"vector_error", quantiles_json(a.vector_error)},
        {"diameter_error", quantiles_json(a.diameter_error)},
        {"mean_velocity", mean},
        {"selected_velocity", selected},
        {"accepted_mispaired", a.accepted_mispaired},
        {"mispaired_weight_share", finite(a.mispaired_weight_share)},
        {"turbulence_intensity", tu},
        {"interfacial_area", compared_json(a.interfacial_area)},
        {"interfacial_area_vs_realised", compared_json(a.interfacial_area_realised)},
        {"interfacial_area_paired", compared_json(a.interfacial_area_paired)},
        {"quality", awcc::to_string(a.quality)},
        {"quality_reason", a.quality == awcc::AwccQuality::ok ? json(nullptr) : json(a.quality_reason)}};
  }
  out["algorithms"] = algorithms;
  const auto& d = v.dual;
  out["dual_tip"] = {{"tips", {d.leading_tip, d.trailing_tip}},
                     {"dx", d.dx},
                     {"dy", d.dy},
                     {"events_status", awcc::to_string(d.events.status)},
                     {"events_reason", d.events.ok() ? json(nullptr) : json(d.events.message)},
                     {"pairing", partner_json(d.pairing)},
                     {"velocity_error", quantiles_json(d.velocity_error)},
                     {"events_velocity", compared_json(d.ed_velocity)},
                     {"events_turbulence_intensity", compared_json(d.ed_turbulence_intensity)},
                     {"awcc_velocity", compared_json(d.awcc_velocity)},
                     {"awcc_turbulence_intensity", compared_json(d.awcc_turbulence_intensity)}};
  if (d.processed.awcc) {
    out["dual_tip"]["awcc_status"] = awcc::to_string(d.processed.awcc->status);
    out["dual_tip"]["awcc_quality"] = awcc::to_string(d.processed.awcc->quality);
  }
  out["seconds_synth"] = v.seconds_synth;
  out["seconds_process"] = v.seconds_process;
  return out;
}

std::vector<MultiTipValidation> validate_multi_tip_repeats(const synth::Scene& scene,
                                                           const MultiTipValidateOptions& options, int repeat,
                                                           const Progress& progress) {
  std::vector<MultiTipValidation> runs;
  for (int i = 0; i < repeat; ++i) {
    synth::Scene s = scene;
    if (repeat > 1) s.seed = awcc::derive_seed(scene.seed, static_cast<std::uint64_t>(i));
    runs.push_back(validate_multi_tip(s, options));
    if (progress) progress(static_cast<double>(i + 1) / repeat);
  }
  return runs;
}

std::vector<ErrorSummary> summarise_multi_tip(const std::vector<MultiTipValidation>& runs) {
  using Get = std::function<std::optional<double>(const MultiTipValidation&)>;
  std::vector<std::pair<std::pair<std::string, std::string>, Get>> series;
  series.push_back({{"pairing errors", "pairing_error"}, [](const MultiTipValidation& v) {
                      const double e = v.pairing_total.error_fraction();
                      return std::isfinite(e) ? std::optional(e) : std::nullopt;
                    }});
  // The algorithms of the first run (every run has the same options).
  const std::size_t algorithms = runs.empty() ? 0 : runs.front().algorithms.size();
  static const char* axes[] = {"x", "y", "z"};
  for (std::size_t a = 0; a < algorithms; ++a) {
    const std::string name(awcc::to_string(runs.front().algorithms[a].result.options.algorithm));
    auto of = [a](const MultiTipValidation& v) -> const VectorValidation* {
      return a < v.algorithms.size() ? &v.algorithms[a] : nullptr;
    };
    series.push_back({{name + " median speed error", name + ".speed_error_median"},
                      [of](const MultiTipValidation& v) -> std::optional<double> {
                        const auto* x = of(v);
                        return x && x->speed_error.count ? std::optional(x->speed_error.median) : std::nullopt;
                      }});
    for (std::size_t i = 0; i < 3; ++i) {
      series.push_back({{fmt::format("{} mean u_{} (/|U|)", name, axes[i]), fmt::format("{}.u_{}", name, axes[i])},
                        [of, i](const MultiTipValidation& v) {
                          const auto* x = of(v);
                          return x ? x->mean_velocity[i].error() : std::nullopt;
                        }});
    }
    for (std::size_t i = 0; i < 3; ++i) {
      series.push_back({{fmt::format("{} Tu_{}", name, axes[i]), fmt::format("{}.tu_{}", name, axes[i])},
                        [of, i](const MultiTipValidation& v) {
                          const auto* x = of(v);
                          return x ? x->turbulence_intensity[i].error() : std::nullopt;
                        }});
    }
    series.push_back({{name + " IAC vs 6c/d_b", name + ".interfacial_area"}, [of](const MultiTipValidation& v) {
                        const auto* x = of(v);
                        return x ? x->interfacial_area.error() : std::nullopt;
                      }});
  }
  series.push_back({{"ED u_x", "events.velocity"}, [](const MultiTipValidation& v) { return v.dual.ed_velocity.error(); }});
  series.push_back({{"ED Tu_x", "events.turbulence_intensity"},
                    [](const MultiTipValidation& v) { return v.dual.ed_turbulence_intensity.error(); }});
  series.push_back({{"AWCC u_x", "awcc.velocity"}, [](const MultiTipValidation& v) { return v.dual.awcc_velocity.error(); }});
  series.push_back({{"AWCC Tu_x", "awcc.turbulence_intensity"},
                    [](const MultiTipValidation& v) { return v.dual.awcc_turbulence_intensity.error(); }});
  std::vector<ErrorSummary> out;
  for (const auto& [names, get] : series) {
    std::vector<double> values;
    for (const auto& r : runs)
      if (const auto e = get(r)) values.push_back(*e);
    out.push_back({names.first, names.second, false, summarise95(values)});
  }
  return out;
}

std::string multi_tip_repeats_report(const std::vector<MultiTipValidation>& runs,
                                     const std::vector<ErrorSummary>& summary, std::uint64_t seed) {
  std::string out = fmt::format("{} runs of the scene (seeds derived from {}); errors in %:\n", runs.size(), seed);
  out += fmt::format("{:<36}{:>8}{:>12}{:>26}\n", "error", "runs", "mean", "95 % interval");
  for (const auto& e : summary) {
    const auto& m = e.summary;
    if (m.count == 0) {
      out += fmt::format("{:<36}{:>8}{:>12}{:>26}\n", e.name, m.count, "n/a", "n/a");
      continue;
    }
    out += fmt::format("{:<36}{:>8}{:>10.3f} %{:>14.3f} % to {:.3f} %\n", e.name, m.count, 100.0 * m.mean,
                       100.0 * m.lower, 100.0 * m.upper);
  }
  // pdp's verdict per algorithm: an error above is only unflagged where the runs were ok.
  const std::size_t algorithms = runs.empty() ? 0 : runs.front().algorithms.size();
  for (std::size_t a = 0; a < algorithms; ++a) {
    std::array<int, 3> levels{};
    for (const auto& r : runs) {
      if (a < r.algorithms.size()) ++levels.at(static_cast<std::size_t>(r.algorithms[a].quality));
    }
    out += fmt::format("{} quality: {} ok, {} low, {} insufficient\n",
                       awcc::to_string(runs.front().algorithms[a].result.options.algorithm), levels[0], levels[1],
                       levels[2]);
  }
  return out;
}

json multi_tip_repeats_to_json(const std::vector<MultiTipValidation>& runs, const std::vector<ErrorSummary>& summary) {
  json j;
  json errors = json::object();
  for (const auto& e : summary) {
    const auto& m = e.summary;
    errors[e.key] = {{"runs", m.count},
                     {"mean", m.count ? json(m.mean) : json(nullptr)},
                     {"ci95", m.count ? json{m.lower, m.upper} : json(nullptr)}};
  }
  j["repeat"] = runs.size();
  j["error"] = errors;
  j["runs"] = json::array();
  for (const auto& r : runs) j["runs"].push_back(multi_tip_to_json(r));
  return j;
}

}  // namespace study
