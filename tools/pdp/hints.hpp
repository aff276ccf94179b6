#pragma once
// The command line's words for what the libraries report by quantity: a
// result whose status a flag would change gets that flag in its message.

#include "awcc/process.hpp"

namespace pdp {

/// Appends the flag to FSCC's and AWCC's messages where one fixes the status
/// (the tip order, the lag range, the tip separation).
void add_flag_hints(awcc::ProcessResult& result);
void add_flag_hints(awcc::FsccResult& result);
void add_flag_hints(awcc::AwccResult& result);

}  // namespace pdp
