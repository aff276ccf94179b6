// The declaration of a probe's tips (tips, leading-tip, tip-channels) and
// the tip pair pdp processes from it: a two-tip declaration processes exactly
// as dx and dy of the same separation; a four-tip one as its leading tip and
// first downstream tip, on the channels mapped; pdp synth's four-tip .h5
// carries its positions back; every mistake of issue 30 refused naming the
// tip or channel, the file and the fix.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "awcc/options.hpp"
#include "awcc/process.hpp"
#include "awcc/serialise.hpp"
#include "awcc/settings_file.hpp"
#include "synth/recording.hpp"
#include "synth/scene.hpp"
#include "synth/synthesiser.hpp"
#include "test_paths.hpp"

namespace {

namespace fs = std::filesystem;
using Points = std::vector<std::array<double, 3>>;

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

awcc::ProcessOptions options(std::vector<awcc::OptionSetting> settings) { return awcc::process_options(settings); }

// The message of the OptionError or InputError `f` throws (empty when none).
template <class F>
std::string refusal(F f) {
  try {
    f();
  } catch (const awcc::OptionError& e) {
    return e.what();
  } catch (const awcc::InputError& e) {
    return e.what();
  }
  return {};
}

// samples/four-tip.toml, shortened, as a FLAC file (no positions in it) or pdp synth's .h5.
synth::Scene four_tips() {
  synth::Scene s;
  synth::load_scene_toml(pdp_test::source_dir() / "samples" / "four-tip.toml", s);
  s.duration = 4.0;
  return s;
}

fs::path written(const std::string& name, const synth::Scene& s) {
  const auto path = pdp_test::test_file(name);
  synth::RecordingOptions o;
  o.format = *synth::format_from_extension(path);
  synth::write_recording(path, s, synth::synthesise(s).signals, o);
  return path;
}

TEST(ProbeTips, TheDeclarationReadsTheTextAndTheSettingsFilePdpSynthReads) {
  // The settings file's [["0mm", ...], ...] is the text of the option, in metres.
  const auto file = pdp_test::source_dir() / "samples" / "four-tip.toml";
  std::string tips;
  for (const auto& s : awcc::read_settings(file))
    if (s.key == "tips") tips = s.text;
  const auto p = options({{"tips", tips, ""}});
  const Points expected = {{0, 0, 0}, {5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {5e-3, 0, 1.5e-3}};
  ASSERT_EQ(p.probe.positions.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    for (std::size_t c = 0; c < 3; ++c) EXPECT_NEAR(p.probe.positions[k][c], expected[k][c], 1e-15) << k << c;
  }
  // pdp synth read the same file through the same parser: the same numbers exactly.
  const auto scene = four_tips();
  ASSERT_EQ(scene.tips.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ((std::array<double, 3>{scene.tips[k].x, scene.tips[k].y, scene.tips[k].z}), p.probe.positions[k]);
  }
  // The declarations are the [probe] table's keys, and their text reads back.
  std::vector<std::string> names;
  for (const auto& f : awcc::probe_option_fields()) names.emplace_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"tips", "leading-tip", "tip-channels"}));
  EXPECT_EQ(options({{"tips", awcc::probe_option_fields()[0].format(p), ""}}).probe.positions, p.probe.positions);
}

TEST(ProbeTips, MistakesInTheDeclarationAreRefusedNamingTheTipAndWhereItWasGiven) {
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0;5,0,0", "probe.toml:2"}}); }),
                  "probe.toml:2: tips: point 1 '5,0,0', coordinate x: 5 has no unit: write 5mm"));
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0;5mm,0", ""}}); }), "point 1 '5mm,0' needs exactly three"));
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0;5mm,0,0;5mm,1mm,0;5mm,0,0", "probe.toml:3"}}); }),
                  "probe.toml:3: tips: tips 1 and 3 are both at (5mm, 0mm, 0mm) (tips are numbered from 0): a tip "
                  "listed twice; correct the position of one of them"));
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0", ""}}); }), "a probe has two or more tips"));
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0;5mm,0,0", ""}, {"dx", "5mm", ""}}); }),
                  "dx (or dy) and tips both declare the probe's geometry"));
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0;5mm,0,0", ""}, {"tip-channels", "1,1", "p.toml:4"}}); }),
                  "p.toml:4: tip-channels: tips 0 and 1 are both mapped to channel 1"));
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0;5mm,0,0", ""}, {"tip-channels", "0,1,2", ""}}); }),
                  "3 channels are given for 2 tips"));
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0;5mm,0,0", ""}, {"leading-tip", "2", ""}}); }),
                  "the leading tip is tip 2, but 2 tips are declared"));
  EXPECT_TRUE(has(refusal([] { options({{"tip-channels", "0,1", ""}}); }), "declare the tips' positions too"));
  EXPECT_TRUE(has(refusal([] { options({{"tips", "0,0,0;5mm,0,0", ""}, {"trailing-channel", "2", ""}}); }),
                  "with tips declared, tip-channels maps each tip to its channel"));
}

TEST(ProbeTips, ATwoTipDeclarationProcessesExactlyAsDxAndDy) {
  synth::Scene s;
  s.duration = 4.0;
  s.fs = 100e3;
  s.dx = 5e-3;
  s.dy = 1e-3;
  const auto flac = written("two.flac", s);
  const auto by_separation = awcc::process_recording(flac, options({{"dx", "5mm", ""}, {"dy", "1mm", ""}}));
  const auto by_tips = awcc::process_recording(flac, options({{"tips", "0,0,0;5mm,1mm,0", ""}}));
  ASSERT_TRUE(by_separation.awcc && by_separation.fscc);
  EXPECT_EQ(by_tips.dx, 5e-3);
  EXPECT_EQ(by_tips.dy, 1e-3);
  auto a = awcc::to_json(by_separation), b = awcc::to_json(by_tips);
  a.erase("seconds");
  b.erase("seconds");
  EXPECT_EQ(a, b);
  // Its tips in the other order, the leading one named: the same pair.
  const auto named = awcc::process_recording(
      flac, options({{"tips", "5mm,1mm,0;0,0,0", ""}, {"leading-tip", "1", ""}, {"tip-channels", "1,0", ""}}));
  auto c = awcc::to_json(named);
  c.erase("seconds");
  EXPECT_EQ(c, a);
}

TEST(ProbeTips, AFourTipDeclarationProcessesItsFirstPairOnTheChannelsMapped) {
  const auto flac = written("four.flac", four_tips());
  // Tip 1 of the declaration is channel 2 (5 mm downstream, 1.5 mm across): the pair is channels 0 and 2.
  // Method both: the tip pair alone, the other channels flagged as not processed.
  const auto declared = awcc::process_recording(flac, options({{"tips", "0,0,0;5mm,1.5mm,0;5mm,0,0;5mm,0,1.5mm", ""},
                                                               {"tip-channels", "0,2,1,3", ""},
                                                               {"method", "both", ""}}));
  const auto pair = awcc::process_recording(
      flac, options({{"dx", "5mm", ""}, {"dy", "1.5mm", ""}, {"trailing-channel", "2", ""}, {"method", "both", ""}}));
  ASSERT_EQ(declared.tips.size(), 2u);
  EXPECT_EQ(declared.tips[1].channel, 2);
  auto a = awcc::to_json(declared), b = awcc::to_json(pair);
  a.erase("seconds");
  b.erase("seconds");
  EXPECT_EQ(a, b);
  EXPECT_TRUE(std::any_of(declared.warnings.begin(), declared.warnings.end(),
                          [](const awcc::Warning& w) { return w.flag == awcc::Flag::channels_ignored; }));
  // By default (method auto) a probe of four tips is processed bubble by
  // bubble: the same pair first, every other tip in the order declared, each
  // on its channel, none ignored; the pair's own results unchanged.
  const auto multi = awcc::process_recording(
      flac, options({{"tips", "0,0,0;5mm,1.5mm,0;5mm,0,0;5mm,0,1.5mm", ""}, {"tip-channels", "0,2,1,3", ""}}));
  ASSERT_TRUE(multi.probe);
  EXPECT_EQ(multi.probe->channels, (std::vector<int>{0, 2, 1, 3}));
  EXPECT_EQ(multi.probe->geometry.positions()[1], (awcc::Vec3{5e-3, 1.5e-3, 0.0}));
  EXPECT_EQ(multi.probe->geometry.positions()[2], (awcc::Vec3{5e-3, 0.0, 0.0}));
  ASSERT_EQ(multi.probe->further_tips.size(), 2u);
  EXPECT_EQ(multi.probe->further_tips[0].channel, 1);
  EXPECT_EQ(multi.probe->pairs.size(), 2u);
  EXPECT_TRUE(std::none_of(multi.warnings.begin(), multi.warnings.end(),
                           [](const awcc::Warning& w) { return w.flag == awcc::Flag::channels_ignored; }));
  ASSERT_TRUE(multi.fscc && declared.fscc);
  EXPECT_EQ(multi.fscc->velocity, declared.fscc->velocity);
  EXPECT_EQ(multi.tips[1].phase.void_fraction, declared.tips[1].phase.void_fraction);
}

TEST(ProbeTips, AFourTipH5FromPdpSynthCarriesItsTipsBack) {
  const auto scene = four_tips();
  const auto h5 = written("four.h5", scene);
  const auto recording = awcc::open_recording(h5);
  const auto& info = recording->info();
  ASSERT_EQ(info.tip_positions.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& t = scene.tips[k];
    EXPECT_EQ(info.tip_positions[k], (std::array<double, 3>{t.x, t.y, t.z})) << k;
  }
  EXPECT_EQ(info.sensor_ids, (std::vector<std::string>{"0", "1", "2", "3"}));
  EXPECT_EQ(info.leading_tip, 0);
  // Processed without any declaration: the file's pair, as dx of its separation.
  const auto from_file = awcc::process_recording(h5, awcc::ProcessOptions{});
  EXPECT_EQ(from_file.dx, 5e-3);
  EXPECT_EQ(awcc::probe_of({}, info).positions, info.tip_positions);
  // The same tips declared (another origin: only separations count) are accepted ...
  EXPECT_NO_THROW(awcc::process_recording(h5, options({{"tips", "1mm,0,0;6mm,0,0;6mm,1.5mm,0;6mm,0,1.5mm", ""}})));
  // ... other tips, or another dx, are refused naming both.
  const auto moved = refusal([&] {
    awcc::process_recording(h5, options({{"tips", "0,0,0;5mm,0,0;5mm,1.5mm,0;5mm,0,1.6mm", ""}}));
  });
  EXPECT_TRUE(has(moved, h5.string() + ": tip 3 (channel 3, sensor 3) is (5mm, 0mm, 1.6mm) from the leading tip as "
                                        "declared (tips), but (5mm, 0mm, 1.5mm) as the file states"))
      << moved;
  const auto dx = refusal([&] { awcc::process_recording(h5, options({{"dx", "6mm", ""}})); });
  EXPECT_TRUE(has(dx, "dx = 6mm is given, but the file states the tips of channels 0 and 1 5mm apart")) << dx;
}

TEST(ProbeTips, ARecordingThatCannotHoldTheDeclaredTipsIsRefusedNamingTheFile) {
  synth::Scene s;
  s.duration = 0.5;
  const auto flac = written("pair.flac", s);
  const auto fewer = refusal([&] {
    awcc::process_recording(flac, options({{"tips", "0,0,0;5mm,0,0;5mm,1.5mm,0;5mm,0,1.5mm", ""}}));
  });
  EXPECT_TRUE(has(fewer, flac.string() + ": 4 tips are declared but the recording holds 2 channels: tip 2 has no "
                                         "channel; record every tip, or declare only the tips recorded"))
      << fewer;
  const auto beyond = refusal(
      [&] { awcc::process_recording(flac, options({{"tips", "0,0,0;5mm,0,0", ""}, {"tip-channels", "0,3", ""}})); });
  EXPECT_TRUE(has(beyond, flac.string() + ": tip 1 is mapped to channel 3, but the recording holds 2 channels"))
      << beyond;
}

}  // namespace
