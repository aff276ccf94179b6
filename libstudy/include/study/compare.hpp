#pragma once
// FSCC and AWCC side by side on one record (pdp compare): a recording, or a
// scene synthesised in memory. Each method is processed alone, as pdp
// process --method fscc and --method awcc process the record
// (awcc::process_binarised), so that each has its own run time.

#include <filesystem>
#include <optional>
#include <string>

#include "awcc/process.hpp"
#include "study/run.hpp"

namespace study {

struct Comparison {
  std::string what;                     ///< the file, or the synthetic scene and its seed
  awcc::FsccResult fscc;
  awcc::AwccResult awcc;
  double fscc_seconds = 0.0, awcc_seconds = 0.0;  ///< wall seconds of each processing
  std::optional<double> truth_velocity, truth_turbulence_intensity;  ///< synthetic scenes only
};

/// Both methods on a binarised record of probe separations dx, dy.
Comparison compare(const awcc::BinarisedRecording& record, const RunOptions& options, double dx, double dy);

/// Both methods on a recording, read and binarised by `reading` (its reader,
/// channels, binarisation and dx); throws as awcc::binarise_recording does.
Comparison compare_recording(const std::filesystem::path& file, const awcc::ProcessOptions& reading,
                             const RunOptions& options);

/// Both methods on a synthesised scene (synthesise_pair).
Comparison compare_scene(const synth::Scene& scene, const RunOptions& options);

/// The side-by-side table: each method's status and AWCC's quality level
/// above the values they qualify, the reasons below.
std::string comparison_report(const Comparison& c);

}  // namespace study
