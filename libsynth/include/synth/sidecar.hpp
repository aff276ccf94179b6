#pragma once
// The JSON sidecar "<name>.truth.json" beside each synthetic recording: the
// scene, probe geometry, fs, seed, toolkit version and the truth. Keys are
// snake_case, values in SI units; documented in docs/output.md.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "synth/bubble_truth.hpp"
#include "synth/recording.hpp"
#include "synth/truth.hpp"

namespace synth {

/// The scene as JSON: every field under its snake_case name, SI units.
nlohmann::json scene_to_json(const Scene& scene);

/// The truth as JSON: "imposed" and "realised" objects and more.
nlohmann::json truth_to_json(const Truth& truth);

/// The whole sidecar for a recording written with `options`. With
/// `bubbles` (the table written beside it at bubble_truth_path(recording)),
/// "bubble_truth" names that file, its rows and columns; else it is null.
nlohmann::json sidecar_json(const Truth& truth, const RecordingOptions& options,
                            const std::filesystem::path& recording, const BubbleTruth* bubbles = nullptr);

/// "dir/rec.flac" -> "dir/rec.truth.json".
std::filesystem::path sidecar_path(const std::filesystem::path& recording);

/// "dir/rec.flac" -> "dir/rec.truth.bubbles.csv", the truth per bubble
/// beside the sidecar (pdp synth with bubble-truth).
std::filesystem::path bubble_truth_path(const std::filesystem::path& recording);

/// The volts per count a synthetic recording's sidecar states, if it has one
/// that does (readers of the recording use it to give voltages).
std::optional<double> sidecar_volts_per_count(const std::filesystem::path& recording);

}  // namespace synth
