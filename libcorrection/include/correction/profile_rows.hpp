#pragma once
// A processed recording as a row of a profile's flow quantities
// (awcc/profile_flow.hpp, METHOD 12): its position, the leading tip's void
// fraction and bubble count rate with their intervals, and the best velocity
// the row has with its uncertainty. The one builder: pdp process, the
// Python module and the report read a profile's rows through it.
//
// The velocity (METHOD 12): the bias-corrected AWCC median with the AWCC
// forest's quantiles where the row is corrected (not when untrusted, nor
// FSCC-forest quantiles, which correct FSCC's velocity and are named so);
// else the velocity of ProcessResult::velocity_source() (AWCC of quality ok,
// else FSCC, else AWCC of quality low) with its 95 % sampling interval. A
// velocity without an interval (FSCC whose segments give none) is left out:
// a value without uncertainty would make every interval too narrow; the
// row's note says so.

#include <optional>
#include <string>

#include "awcc/process.hpp"
#include "awcc/profile_flow.hpp"
#include "correction/model.hpp"

namespace correction {

struct ProfileRowOf {
  awcc::ProfileRow row;
  std::string note;  ///< why the row has no velocity, or empty
};

/// The row of `result` at `position` (m); `correction` when pdp process
/// --correct ran.
ProfileRowOf profile_row(const awcc::ProcessResult& result, double position, const Correction* correction = nullptr);

}  // namespace correction
