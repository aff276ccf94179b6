#include "correction/profile_rows.hpp"

#include <fmt/format.h>

namespace correction {

ProfileRowOf profile_row(const awcc::ProcessResult& r, double position, const Correction* correction) {
  ProfileRowOf out;
  auto& row = out.row;
  row.name = r.info.path.filename().string();
  row.y = position;
  const auto& lead = r.tips.at(0).phase;
  row.c = lead.void_fraction;
  row.c_ci95 = lead.void_fraction_ci95;
  row.bubble_frequency = lead.bubble_count_rate;
  row.bubble_frequency_ci95 = lead.bubble_count_rate_ci95;
  if (correction && correction->corrected() && correction->forest == "awcc" && correction->velocity) {
    row.u = correction->velocity->median();
    row.u_source = awcc::FlowVelocitySource::corrected_awcc;
    for (std::size_t i = 0; i < correction_levels.size(); ++i) {
      row.u_quantiles.push_back({correction_levels[i], correction->velocity->quantiles[i]});
    }
    return out;
  }
  switch (r.velocity_source()) {
    case awcc::VelocitySource::awcc:
      row.u = r.awcc->velocity;
      row.u_source = awcc::FlowVelocitySource::awcc;
      row.u_ci95 = r.awcc->velocity_ci95;
      break;
    case awcc::VelocitySource::fscc:
      if (r.fscc->velocity_ci95) {
        row.u = r.fscc->velocity;
        row.u_source = awcc::FlowVelocitySource::fscc;
        row.u_ci95 = *r.fscc->velocity_ci95;
      } else {
        out.note = fmt::format("{}: FSCC's velocity {:.3f} m/s has no sampling interval (too few segments hold a "
                               "peak): left out of the discharge",
                               row.name, r.fscc->velocity);
      }
      break;
    case awcc::VelocitySource::none:
      out.note = fmt::format("{}: no velocity (neither AWCC nor FSCC gave one)", row.name);
      break;
  }
  return out;
}

}  // namespace correction
