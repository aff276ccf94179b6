#include "study/profile_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <fstream>
#include <map>
#include <mutex>

#include "awcc/csv.hpp"
#include "awcc/errors.hpp"
#include "awcc/parallel.hpp"
#include "awcc/read_back.hpp"
#include "awcc/serialise.hpp"
#include "awcc/units.hpp"
#include "correction/profile_rows.hpp"
#include "synth/sidecar.hpp"

namespace study {

namespace {

double length_of(const std::string& text, const std::string& where) {
  try {
    return awcc::parse_quantity(text, awcc::Dimension::length);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{}: {}", where, e.what()));
  }
}

std::string name_of(const std::string& file) { return std::filesystem::path(file).filename().string(); }

}  // namespace

std::vector<std::optional<double>> positions_of_list(std::span<const std::string> lengths,
                                                     std::span<const std::string> files, const std::string& source) {
  if (lengths.size() != files.size()) {
    throw std::invalid_argument(
        fmt::format("{} gives {} positions for {} files; give one per file", source, lengths.size(), files.size()));
  }
  std::vector<std::optional<double>> out;
  for (const auto& text : lengths) out.emplace_back(length_of(text, source));
  check_distinct_positions(out, files, source);
  return out;
}

std::vector<std::string> files_of_manifest(const std::filesystem::path& manifest) {
  std::ifstream in(manifest);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot read the manifest", manifest.string()));
  std::vector<std::string> out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto cells = awcc::split_cells(line);
    if (cells.size() < 2 || cells[0].empty() || (number == 1 && cells[0] == "file")) continue;
    const std::filesystem::path file(cells[0]);
    out.push_back((file.is_absolute() ? file : manifest.parent_path() / file).string());
  }
  if (out.empty()) {
    throw std::invalid_argument(fmt::format("{}: the manifest names no recording (rows file,position)",
                                            manifest.string()));
  }
  return out;
}

std::vector<std::optional<double>> positions_of_manifest(const std::filesystem::path& manifest,
                                                         std::span<const std::string> files) {
  const std::string where = manifest.string();
  std::ifstream in(manifest);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot read the manifest", where));
  std::map<std::string, double> by_name;
  std::map<std::string, int> line_of;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto cells = awcc::split_cells(line);
    if (cells.size() < 2) continue;
    double position = 0.0;
    try {
      position = awcc::parse_quantity(cells[1], awcc::Dimension::length);
    } catch (const std::invalid_argument& e) {
      if (number == 1) continue;  // header row
      throw std::invalid_argument(fmt::format("{}:{}: {}", where, number, e.what()));
    }
    const auto name = name_of(cells[0]);
    if (const auto [at, fresh] = line_of.emplace(name, number); !fresh) {
      throw std::invalid_argument(
          fmt::format("{}: lines {} and {} both position {}; keep one", where, at->second, number, name));
    }
    by_name[name] = position;
  }
  std::vector<std::optional<double>> out(files.size());
  std::map<std::string, std::string> seen;
  for (std::size_t i = 0; i < files.size(); ++i) {
    const auto name = name_of(files[i]);
    if (const auto [at, fresh] = seen.emplace(name, files[i]); !fresh) {
      throw std::invalid_argument(fmt::format("{} and {} share the name {}, which the manifest matches by: rename "
                                              "one or give the positions as a list",
                                              at->second, files[i], name));
    }
    if (const auto it = by_name.find(name); it != by_name.end()) out[i] = it->second;
  }
  check_distinct_positions(out, files, where);
  return out;
}

std::string manifest_text(std::span<const std::string> names, std::span<const double> positions) {
  if (names.size() != positions.size()) throw std::invalid_argument("manifest_text: one position per name");
  std::string out = "file,position\n";
  for (std::size_t i = 0; i < names.size(); ++i) {
    out += fmt::format("{},{}\n", names[i], awcc::format_quantity(positions[i], awcc::Dimension::length));
  }
  return out;
}

void check_distinct_positions(std::span<const std::optional<double>> positions, std::span<const std::string> files,
                              const std::string& source) {
  // Only the positioned files take part; their indices map back to the files.
  std::vector<double> y;
  std::vector<std::size_t> file_of;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    if (!positions[i]) continue;
    y.push_back(*positions[i]);
    file_of.push_back(i);
  }
  const auto pair = awcc::repeated_position_pair(y);
  if (!pair) return;
  const auto i = file_of[pair->first], j = file_of[pair->second];
  throw std::invalid_argument(fmt::format("{} gives {} and {} the same position, {}; a profile has one recording "
                                          "per position: correct the position, or process the repeat on its own",
                                          source, files[i], files[j],
                                          awcc::format_quantity(*positions[i], awcc::Dimension::length)));
}

ProfileRun process_profile(std::span<const std::string> files, std::span<const std::optional<double>> positions,
                           const ProfileRunOptions& options) {
  if (!positions.empty() && positions.size() != files.size()) {
    throw std::invalid_argument("process_profile: one position per file, or none");
  }
  if (options.model) {
    const auto why = options.model->mismatch(correction::processing_of(options.processing.awcc_options));
    if (!why.empty()) {
      throw std::invalid_argument(fmt::format("the correction model was trained on results processed otherwise ({}); "
                                              "process with the model's settings or train a model for these",
                                              why));
    }
  }
  const std::size_t n = files.size();
  std::vector<std::optional<awcc::ProcessResult>> processed(n);
  std::vector<std::exception_ptr> failed(n);
  std::vector<std::string> skipped(n);
  // FFT plans are kept per thread and reused from record to record.
  std::mutex pool_mutex;
  std::vector<std::unique_ptr<awcc::ProcessWorkspace>> pool;
  std::atomic<std::size_t> done{0};
  const unsigned threads = awcc::thread_count(options.threads, n);
  awcc::parallel_for(n, static_cast<int>(threads), [&](std::size_t i) {
    std::unique_ptr<awcc::ProcessWorkspace> workspace;
    {
      std::lock_guard lock(pool_mutex);
      if (!pool.empty()) {
        workspace = std::move(pool.back());
        pool.pop_back();
      }
    }
    if (!workspace) workspace = std::make_unique<awcc::ProcessWorkspace>();
    awcc::ProcessOptions file_options = options.processing;
    file_options.hash_input = options.hash_inputs;
    // Files side by side already keep both cores busy.
    if (threads > 1) file_options.read_ahead = false;
    // A synthetic recording's sidecar states its volts per count.
    if (!(file_options.reader.volts_per_count > 0.0)) {
      if (const auto vpc = synth::sidecar_volts_per_count(files[i])) file_options.reader.volts_per_count = *vpc;
    }
    try {
      processed[i] = awcc::process_recording(files[i], file_options, *workspace);
      if (options.on_result) options.on_result(*processed[i]);
    } catch (const awcc::InputError& e) {
      // Among several inputs (a glob), a file that is not a recording is
      // skipped and said; a damaged recording still stops the profile.
      if (n == 1 || e.quantity() != "not_a_recording") failed[i] = std::current_exception();
      else skipped[i] = e.what();
    } catch (...) {
      failed[i] = std::current_exception();
    }
    {
      std::lock_guard lock(pool_mutex);
      pool.push_back(std::move(workspace));
    }
    if (options.progress) options.progress(static_cast<double>(++done) / static_cast<double>(n));
  });
  ProfileRun run;
  run.single = n == 1;
  for (std::size_t i = 0; i < n; ++i) {
    if (failed[i]) std::rethrow_exception(failed[i]);
    if (!skipped[i].empty()) {
      run.skipped.push_back(skipped[i]);
      continue;
    }
    const auto position = positions.empty() ? std::nullopt : positions[i];
    if (!options.manifest.empty() && !position) {
      const auto name = name_of(files[i]);
      throw std::invalid_argument(
          fmt::format("{}: no position for {}; add a row '{},<position>'", options.manifest, name, name));
    }
    run.results.push_back(std::move(*processed[i]));
    run.positions.push_back(position);
    run.inputs.push_back(files[i]);
  }
  if (run.results.empty()) throw awcc::InputError(fmt::format("none of the {} inputs is a recording", n));
  if (options.model) {
    for (const auto& r : run.results) run.corrections.push_back(options.model->correct(correction::measurement_of(r)));
  }
  // A profile's flow quantities (METHOD 12): every recording kept has a
  // position. A profile (several files) whose files were all skipped but
  // one still has its flow, refused with the reason.
  if (n >= 2 && std::all_of(run.positions.begin(), run.positions.end(),
                            [](const std::optional<double>& y) { return y.has_value(); })) {
    std::vector<correction::ProfileRowOf> rows;
    for (std::size_t i = 0; i < run.results.size(); ++i) {
      rows.push_back(correction::profile_row(run.results[i], *run.positions[i],
                                             options.model ? &run.corrections[i] : nullptr));
    }
    run.flow = correction::profile_flow_of(std::move(rows), options.flow);
  }
  return run;
}

std::vector<std::string> ProfileRun::warnings() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < corrections.size(); ++i) {
    const auto& c = corrections[i];
    const std::string file = results[i].info.path.string();
    if (!c.corrected()) out.push_back(fmt::format("{}: not corrected: {}", file, c.why_not()));
    for (const auto& note : c.notes) out.push_back(fmt::format("{}: {}", file, note));
    if (c.large_bubbles) out.push_back(fmt::format("{}: {}", file, c.turbulence_message));
  }
  if (flow) {
    for (const auto& w : flow->warnings()) out.push_back(w);
  }
  return out;
}

nlohmann::json profile_run_json(const ProfileRun& run, const std::string& model_name) {
  const bool corrected = !run.corrections.empty();
  auto correction_json = [&](std::size_t i) {
    auto c = correction::to_json(run.corrections[i]);
    c["model"] = model_name;
    return c;
  };
  nlohmann::json j;
  if (run.single && run.results.size() == 1) {
    j = awcc::to_json(run.results[0]);
    if (corrected) j["correction"] = correction_json(0);
    return j;
  }
  j["profile"] = nlohmann::json::array();
  for (std::size_t i = 0; i < run.results.size(); ++i) {
    auto row = awcc::to_json(run.results[i]);
    row[awcc::process_key::position] =
        run.positions[i] ? nlohmann::json(*run.positions[i]) : nlohmann::json(nullptr);
    if (corrected) row["correction"] = correction_json(i);
    j["profile"].push_back(row);
  }
  if (!run.skipped.empty()) j["skipped"] = run.skipped;
  if (run.flow) j[awcc::process_key::flow] = awcc::to_json(*run.flow);
  return j;
}

}  // namespace study
