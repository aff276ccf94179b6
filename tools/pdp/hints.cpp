#include "hints.hpp"

namespace pdp {

void add_flag_hints(awcc::FsccResult& f) {
  switch (f.status) {
    case awcc::FsccStatus::non_positive_lag:
    case awcc::FsccStatus::tips_swapped: f.message += " (--leading-channel/--trailing-channel)"; break;
    case awcc::FsccStatus::peak_at_lag_range_end: f.message += " (--max-lag)"; break;
    case awcc::FsccStatus::no_tip_separation: f.message += " (--dx)"; break;
    default: break;
  }
}

void add_flag_hints(awcc::AwccResult& a) {
  switch (a.status) {
    case awcc::AwccStatus::no_tip_separation: a.message += " (--dx)"; break;
    case awcc::AwccStatus::too_few_particles: a.message += " (--np)"; break;
    case awcc::AwccStatus::tips_swapped: a.message += " (--leading-channel/--trailing-channel)"; break;
    default: break;
  }
}

void add_flag_hints(awcc::ProcessResult& r) {
  if (r.fscc) add_flag_hints(*r.fscc);
  if (r.awcc) add_flag_hints(*r.awcc);
}

}  // namespace pdp
