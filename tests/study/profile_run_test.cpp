// Tests of study/profile_run.hpp: the same profile whatever the thread count,
// the manifest read back as written, a repeated position refused naming both
// files, a non-recording among several skipped and said.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "awcc/json_text.hpp"
#include "study/profile_run.hpp"
#include "synth/recording.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

// Three short recordings of a shallow profile, written as pdp synth writes them.
std::vector<std::string> profile_files(const std::string& tag) {
  std::vector<std::string> files;
  for (int i = 0; i < 3; ++i) {
    synth::Scene s;
    s.velocity = 2.0 + 0.5 * i;
    s.tu = 0.1;
    s.tu_y = s.tu_z = 0.05;
    s.void_fraction = 0.1 + 0.15 * i;
    s.bubble_diameter = 2e-3;
    s.time_scale = 20e-3;
    s.fs = 50e3;
    s.duration = 4.0;
    s.dy = 0.0;
    s.seed = 40 + static_cast<std::uint64_t>(i);
    const auto path = pdp_test::test_file(tag + "-" + std::to_string(i) + ".flac");
    const auto syn = synth::synthesise(s);
    synth::write_recording(path, s, syn.signals);
    files.push_back(path.string());
  }
  return files;
}

// The JSON without its run times (keys starting "seconds"), which differ from run to run.
void drop_times(nlohmann::json& j) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end();) {
      if (it.key().rfind("seconds", 0) == 0) it = j.erase(it);
      else drop_times(*it++);
    }
  } else if (j.is_array()) {
    for (auto& v : j) drop_times(v);
  }
}

TEST(ProfileRun, SameProfileWhateverTheThreadCount) {
  const auto files = profile_files("threads");
  const std::vector<std::optional<double>> positions{5e-3, 15e-3, 30e-3};
  std::string texts[2];
  for (int threads : {1, 2}) {
    study::ProfileRunOptions o;
    o.threads = threads;
    o.flow.draws = 200;
    auto run = study::process_profile(files, positions, o);
    ASSERT_EQ(run.results.size(), 3u);
    ASSERT_TRUE(run.flow.has_value());
    auto j = study::profile_run_json(run, "");
    drop_times(j);
    texts[threads - 1] = awcc::json_text(j);
  }
  EXPECT_EQ(texts[0], texts[1]);
}

TEST(ProfileRun, TheManifestIsReadAsWritten) {
  const std::vector<std::string> names{"a.flac", "b.flac", "c.flac"};
  const std::vector<double> y{2e-3, 8e-3, 14e-3};
  const auto path = pdp_test::test_file("positions.csv");
  std::ofstream(path) << study::manifest_text(names, y);
  // Inputs given with folders and in another order: matched by name.
  const std::vector<std::string> files{"/data/c.flac", "b.flac", "x/a.flac", "readme.txt"};
  const auto got = study::positions_of_manifest(path, files);
  ASSERT_EQ(got.size(), 4u);
  EXPECT_DOUBLE_EQ(*got[0], 14e-3);
  EXPECT_DOUBLE_EQ(*got[1], 8e-3);
  EXPECT_DOUBLE_EQ(*got[2], 2e-3);
  EXPECT_FALSE(got[3].has_value());
}

TEST(ProfileRun, ARepeatedPositionIsRefusedNamingBothFiles) {
  const std::vector<std::string> files{"r1.wav", "r2.wav", "r3.wav"};
  const std::vector<std::string> lengths{"2mm", "5mm", "2mm"};
  try {
    study::positions_of_list(lengths, files, "--positions");
    FAIL() << "a repeated position was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--positions gives r1.wav and r3.wav the same position, 2mm; a profile has one "
                                     "recording per position: correct the position, or process the repeat on its own");
  }
  EXPECT_THROW(study::positions_of_list(std::vector<std::string>{"2mm"}, files, "positions"), std::invalid_argument);
}

TEST(ProfileRun, ANonRecordingAmongSeveralIsSkippedAndSaid) {
  auto files = profile_files("skip");
  const auto text = pdp_test::test_file("notes.txt");
  std::ofstream(text) << "not a recording\n";
  files.insert(files.begin() + 1, text.string());
  study::ProfileRunOptions o;
  o.flow.draws = 0;
  const auto run = study::process_profile(files, {}, o);
  EXPECT_EQ(run.results.size(), 3u);
  ASSERT_EQ(run.skipped.size(), 1u);
  EXPECT_NE(run.skipped[0].find("notes.txt"), std::string::npos) << run.skipped[0];
  EXPECT_FALSE(run.flow.has_value());  // no positions: no flow
  // Alone, the same file is an error, not a skip.
  EXPECT_THROW(study::process_profile(std::vector<std::string>{text.string()}, {}, o), awcc::InputError);
}

}  // namespace
