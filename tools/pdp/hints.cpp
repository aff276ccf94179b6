#include "hints.hpp"

#include <string>
#include <string_view>

#include "command.hpp"

namespace pdp {

namespace {

// The options (declared names) that change a status, as the running command's flags.
void hint(std::string& message, std::string_view options) {
  if (const auto flags = flags_for(options); !flags.empty()) message += " (" + flags + ")";
}

}  // namespace

void add_flag_hints(awcc::FsccResult& f) {
  switch (f.status) {
    case awcc::FsccStatus::non_positive_lag:
    case awcc::FsccStatus::tips_swapped: hint(f.message, "leading-channel,trailing-channel"); break;
    case awcc::FsccStatus::peak_at_lag_range_end: hint(f.message, "max-lag"); break;
    case awcc::FsccStatus::no_tip_separation: hint(f.message, "dx"); break;
    default: break;
  }
}

void add_flag_hints(awcc::AwccResult& a) {
  switch (a.status) {
    case awcc::AwccStatus::no_tip_separation: hint(a.message, "dx"); break;
    case awcc::AwccStatus::too_few_particles: hint(a.message, "np"); break;
    case awcc::AwccStatus::tips_swapped: hint(a.message, "leading-channel,trailing-channel"); break;
    default: break;
  }
}

void add_flag_hints(awcc::ProcessResult& r) {
  if (r.fscc) add_flag_hints(*r.fscc);
  if (r.awcc) add_flag_hints(*r.awcc);
}

}  // namespace pdp
