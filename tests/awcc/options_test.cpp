// Options applied once (awcc::process_options, awcc::method_options over
// awcc::apply_settings) and validated one way (awcc::Validation): what a
// settings file gives and what a call (the command line, Python) gives are
// the same struct and the same error; every error names the option by its
// declared name.
#include "awcc/options.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "awcc/csv.hpp"
#include "awcc/read_back.hpp"
#include "awcc/settings_file.hpp"
#include "test_paths.hpp"

namespace {

using awcc::OptionError;
using awcc::OptionSetting;
using awcc::ProcessOptions;
using awcc::Validation;
using awcc::ValidationStatus;

// Every declared option's value as text: equal texts, equal options.
template <class T>
void add_texts(std::string& out, std::span<const awcc::OptionField<T>> fields, const T& o) {
  for (const auto& f : fields) out += std::string(f.name) + "=" + f.format(o) + "\n";
}
std::string texts(const ProcessOptions& p) {
  std::string out;
  add_texts(out, awcc::process_option_fields(), p);
  add_texts(out, awcc::reader_option_fields(), p.reader);
  add_texts(out, awcc::binarisation_option_fields(), p.binarisation);
  add_texts(out, awcc::fscc_option_fields(), p.fscc_options);
  add_texts(out, awcc::awcc_option_fields(), p.awcc_options);
  add_texts(out, awcc::structure_option_fields(), p.structure);
  return out;
}

std::set<std::string> declared_names() {
  std::set<std::string> names;
  auto add = [&](auto fields) {
    for (const auto& f : fields) names.insert(std::string(f.name));
  };
  add(awcc::process_option_fields());
  add(awcc::reader_option_fields());
  add(awcc::binarisation_option_fields());
  add(awcc::fscc_option_fields());
  add(awcc::awcc_option_fields());
  add(awcc::structure_option_fields());
  return names;
}

// A settings file's keys as settings, each with its origin FILE:LINE.
std::vector<OptionSetting> from_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  std::vector<OptionSetting> out;
  for (const auto& s : awcc::read_settings(path)) {
    out.push_back({s.key, s.text, path.string() + ":" + std::to_string(s.line)});
  }
  return out;
}

OptionError error_of(std::span<const OptionSetting> settings) {
  try {
    (void)awcc::process_options(settings);
  } catch (const OptionError& e) {
    return e;
  }
  ADD_FAILURE() << "accepted";
  return OptionError("");
}

TEST(ProcessOptions, AFileAndACallGiveTheSameOptions) {
  const auto file = from_file(pdp_test::test_file("options.toml"),
                              "dx = \"7.15mm\"\n"
                              "np = 7\n"
                              "method = \"awcc\"\n"
                              "threshold-rule = \"fixed\"\n"
                              "threshold = \"2.5V\"\n"
                              "subsample = \"parabolic\"\n"
                              "probe-correction = true\n"
                              "velocity-range = \"0.5m/s,20m/s\"\n"
                              "arrival-length-classes = [\"1mm\", \"3mm\"]\n");
  const std::vector<OptionSetting> call{{"dx", "7.15mm", ""},          {"np", "7", ""},
                                        {"method", "awcc", ""},         {"threshold-rule", "fixed", ""},
                                        {"threshold", "2.5V", ""},      {"subsample", "parabolic", ""},
                                        {"probe-correction", "on", ""}, {"velocity-range", "0.5m/s,20m/s", ""},
                                        {"arrival-length-classes", "1mm,3mm", ""}};
  const auto a = awcc::process_options(file);
  const auto b = awcc::process_options(call);
  EXPECT_EQ(texts(a), texts(b));
  EXPECT_NE(texts(a), texts(ProcessOptions{}));
  EXPECT_DOUBLE_EQ(a.dx, 7.15e-3);
  EXPECT_EQ(a.awcc_options.np, 7);
  EXPECT_TRUE(a.awcc && !a.fscc);
  EXPECT_DOUBLE_EQ(*a.binarisation.fixed_threshold, 2.5);  // read under the rule given before it
  EXPECT_TRUE(a.awcc_options.probe_correction.enabled);
  // FSCC refines its peak as AWCC does: the one subsample option sets both.
  EXPECT_EQ(a.awcc_options.subsample, awcc::Subsample::parabolic);
  EXPECT_EQ(a.fscc_options.subsample, awcc::Subsample::parabolic);
}

TEST(ProcessOptions, ARefusedValueGivesTheSameErrorFromAFileAndACall) {
  const auto path = pdp_test::test_file("bad.toml");
  const auto from_a_file = error_of(from_file(path, "dx = \"5mm\"\nfilter-a = 2\n"));
  const std::vector<OptionSetting> call{{"dx", "5mm", ""}, {"filter-a", "2", ""}};
  const auto from_a_call = error_of(call);
  EXPECT_EQ(from_a_call.quantity(), "filter-a");
  EXPECT_EQ(from_a_file.quantity(), "filter-a");
  EXPECT_EQ(std::string(from_a_call.what()), "filter-a: A = 2 must lie in [0, 1]");
  EXPECT_EQ(std::string(from_a_file.what()), path.string() + ":2: " + from_a_call.what());
}

TEST(ProcessOptions, EveryRefusedValueNamesItsOptionByItsDeclaredName) {
  // Text no option takes: each option that refuses it names itself.
  const auto names = declared_names();
  int refused = 0;
  for (const auto& name : names) {
    const std::vector<OptionSetting> s{{name, "@@", ""}};
    try {
      (void)awcc::process_options(s);
    } catch (const OptionError& e) {
      ++refused;
      EXPECT_EQ(e.quantity(), name) << e.what();
      EXPECT_EQ(std::string(e.what()).rfind(name + ": ", 0), 0u) << e.what();
      EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << "a flag in a library message: " << e.what();
    }
  }
  // Only the free-text lists (dataset, variable, tdms-channels) take "@@".
  EXPECT_EQ(refused, static_cast<int>(names.size()) - 3);
}

TEST(ProcessOptions, APresetFillsWhatTheUserDoesNotGive) {
  const std::vector<OptionSetting> felder{{"preset", "felder", ""}};
  const auto p = awcc::process_options(felder);
  EXPECT_EQ(p.fscc_options.segments, 15);
  EXPECT_TRUE(p.fscc && !p.awcc);
  const std::vector<OptionSetting> over{{"segments", "3", ""}, {"preset", "felder", ""}};
  EXPECT_EQ(awcc::process_options(over).fscc_options.segments, 3);  // the user's value wins, wherever listed
  // Both published programs' presets keep the whole-sample peak (METHOD 4.3).
  EXPECT_EQ(p.awcc_options.subsample, awcc::Subsample::none);
  EXPECT_EQ(p.fscc_options.subsample, awcc::Subsample::none);
  const std::vector<OptionSetting> kramer{{"preset", "kramer", ""}, {"subsample", "triangle", "cli"}};
  const auto k = awcc::process_options(std::vector<OptionSetting>{{"preset", "kramer", ""}});
  EXPECT_EQ(k.awcc_options.subsample, awcc::Subsample::none);
  EXPECT_EQ(k.awcc_options.signal, awcc::CorrelationSignal::raw);
  EXPECT_EQ(k.binarisation.rule, awcc::ThresholdRule::kramer);
  EXPECT_EQ(awcc::process_options(kramer).fscc_options.subsample, awcc::Subsample::triangle);  // the user's wins
  const std::vector<OptionSetting> nope{{"preset", "nope", "a.toml:4"}};
  const auto unknown = error_of(nope);
  EXPECT_EQ(unknown.quantity(), "preset");
  EXPECT_EQ(std::string(unknown.what()), "a.toml:4: preset: 'nope' is not a preset; the presets are: felder, kramer");
  // The preset's threshold 0.5 is a fraction; under the user's fixed rule it needs a voltage.
  const std::vector<OptionSetting> clash{{"preset", "felder", ""}, {"threshold-rule", "fixed", ""}};
  const auto e = error_of(clash);
  EXPECT_EQ(e.quantity(), "threshold");
  EXPECT_EQ(std::string(e.what()).rfind("preset felder: threshold: ", 0), 0u) << e.what();
}

TEST(ProcessOptions, AnUnknownNameIsRefusedNamingIt) {
  const std::vector<OptionSetting> s{{"filter_a", "0.3", ""}};
  const auto e = error_of(s);
  EXPECT_EQ(e.quantity(), "filter_a");
  EXPECT_NE(std::string(e.what()).find("'filter_a' is not the declared name"), std::string::npos) << e.what();
}

TEST(ProcessOptions, ImplausibleAndInvalidValuesNameTheOptionThatFixesThem) {
  const std::vector<OptionSetting> far{{"dx", "715mm", ""}};
  EXPECT_EQ(error_of(far).quantity(), "allow-unusual");
  const std::vector<OptionSetting> allowed{{"dx", "715mm", ""}, {"allow-unusual", "on", ""}};
  EXPECT_DOUBLE_EQ(awcc::process_options(allowed).dx, 0.715);
  const std::vector<OptionSetting> same{{"leading-channel", "1", ""}, {"trailing-channel", "1", ""}};
  EXPECT_EQ(error_of(same).quantity(), "leading-channel,trailing-channel");
}

TEST(MethodOptions, ApplyAwccAndFsccWithTheSubsampleRule) {
  awcc::AwccOptions a;
  awcc::FsccOptions f;
  const std::vector<OptionSetting> s{{"subsample", "parabolic", ""}, {"np", "12", ""}, {"segments", "4", ""}};
  awcc::method_options(s, a, f);
  EXPECT_EQ(a.np, 12);
  EXPECT_EQ(f.segments, 4);
  EXPECT_EQ(f.subsample, awcc::Subsample::parabolic);
  const std::vector<OptionSetting> not_a_method{{"dx", "5mm", ""}};
  EXPECT_THROW(awcc::method_options(not_a_method, a, f), OptionError);
  const std::vector<OptionSetting> windows{{"windows-reported", "40", ""}, {"windows-ok", "39", ""}};
  try {
    awcc::method_options(windows, a, f);
    FAIL() << "windows ok below windows reported accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.quantity(), "windows-ok");
  }
}

// One validation style: each options struct's validate() fails with the
// declared name of the option for one bad value and is ok at its limit.
template <class T>
void expect_limit(const char* what, T at_limit, T beyond, const std::string& quantity,
                  ValidationStatus status = ValidationStatus::invalid) {
  SCOPED_TRACE(what);
  const auto ok = at_limit.validate();
  EXPECT_TRUE(ok.ok()) << ok.message;
  EXPECT_TRUE(ok.message.empty() && ok.quantity.empty());
  const auto bad = beyond.validate();
  EXPECT_EQ(bad.status, status) << bad.message;
  EXPECT_EQ(bad.quantity, quantity) << bad.message;
  EXPECT_FALSE(bad.message.empty());
  EXPECT_EQ(bad.message.find("--"), std::string::npos) << "a flag in a library message: " << bad.message;
  if (!quantity.empty()) {
    const auto names = declared_names();
    for (const auto& name : awcc::split_cells(quantity)) EXPECT_TRUE(names.count(name)) << name << " is not declared";
  }
  try {
    bad.throw_if_failed();
    ADD_FAILURE() << "no error thrown";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.quantity(), quantity);
    EXPECT_EQ(std::string(e.what()), bad.message);
  }
}

template <class T, class Edit>
T edited(Edit edit) {
  T o;
  edit(o);
  return o;
}

TEST(Validation, EachOptionsStructNamesTheOptionBeyondItsLimit) {
  using namespace awcc;
  expect_limit("fscc segments", edited<FsccOptions>([](auto& o) { o.segments = 1; }),
               edited<FsccOptions>([](auto& o) { o.segments = 0; }), "segments");
  expect_limit("fscc max lag", edited<FsccOptions>([](auto& o) { o.max_lag = 1e-9; }),
               edited<FsccOptions>([](auto& o) { o.max_lag = 0.0; }), "max-lag");
  expect_limit("awcc np", edited<AwccOptions>([](auto& o) { o.np = 1000; }),
               edited<AwccOptions>([](auto& o) { o.np = 1001; }), "np");
  expect_limit("awcc filter A", edited<AwccOptions>([](auto& o) { o.filter_a = 1.0; }),
               edited<AwccOptions>([](auto& o) { o.filter_a = 1.0 + 1e-12; }), "filter-a");
  expect_limit("awcc windows ok", edited<AwccOptions>([](auto& o) { o.windows_ok = o.windows_reported; }),
               edited<AwccOptions>([](auto& o) { o.windows_ok = o.windows_reported - 1; }), "windows-ok");
  expect_limit("probe angle", edited<ProbeCorrectionOptions>([](auto& o) { o.probe_angle = std::numbers::pi; }),
               edited<ProbeCorrectionOptions>([](auto& o) { o.probe_angle = 3.15; }), "probe-angle");
  expect_limit("contact factor", edited<ProbeCorrectionOptions>([](auto& o) { o.contact_factor = 0.0; }),
               edited<ProbeCorrectionOptions>([](auto& o) { o.contact_factor = -0.1; }), "contact-factor");
  expect_limit("probe correction within AWCC's",
               edited<AwccOptions>([](auto& o) { o.probe_correction.needle_diameter = 1e-6; }),
               edited<AwccOptions>([](auto& o) { o.probe_correction.needle_diameter = 0.0; }), "needle-diameter");
  expect_limit("threshold fraction", edited<BinarisationOptions>([](auto& o) { o.theta = 0.999; }),
               edited<BinarisationOptions>([](auto& o) { o.theta = 1.0; }), "threshold");
  expect_limit("histogram bin", edited<BinarisationOptions>([](auto& o) { o.bin_width = 0.0; }),
               edited<BinarisationOptions>([](auto& o) { o.bin_width = -1e-9; }), "bin-width");
  expect_limit("arrival bins", edited<StructureOptions>([](auto& o) { o.arrivals.bins = 1; }),
               edited<StructureOptions>([](auto& o) { o.arrivals.bins = 0; }), "arrival-bins");
  expect_limit("chord time range",
               edited<StructureOptions>([](auto& o) { o.chord_time.max = o.chord_time.bin_width; }),
               edited<StructureOptions>([](auto& o) { o.chord_time.max = 0.5 * o.chord_time.bin_width; }),
               "chord-time-max");
  expect_limit("spectrum segment", edited<SpectrumOptions>([](auto& o) { o.segment_length = 8; }),
               edited<SpectrumOptions>([](auto& o) { o.segment_length = 7; }), "spectrum-segment");
  expect_limit("dx", edited<ProcessOptions>([](auto& o) { o.dx = 0.0; }),
               edited<ProcessOptions>([](auto& o) { o.dx = -1e-3; }), "dx");
  expect_limit("tips", edited<ProcessOptions>([](auto& o) { o.trailing_channel = 2; }),
               edited<ProcessOptions>([](auto& o) { o.trailing_channel = o.leading_channel; }),
               "leading-channel,trailing-channel");
  expect_limit("a part's within the run's", ProcessOptions{},
               edited<ProcessOptions>([](auto& o) { o.awcc_options.np = 0; }), "np");
  expect_limit("plausible dx", edited<ProcessOptions>([](auto& o) { o.dx = 0.1e-3; }),
               edited<ProcessOptions>([](auto& o) { o.dx = 0.0999e-3; }), "allow-unusual",
               ValidationStatus::implausible);
  expect_limit("allowed", edited<ProcessOptions>([](auto& o) { o.dx = 0.0999e-3, o.allow_unusual = true; }),
               edited<ProcessOptions>([](auto& o) { o.reader.fs = 999.0; }), "allow-unusual",
               ValidationStatus::implausible);
}

}  // namespace

namespace {

// An option's formatted value, found by its declared name.
template <class T>
std::string formatted(std::span<const awcc::OptionField<T>> fields, std::string_view name, const T& o) {
  for (const auto& f : fields) {
    if (f.name == name) return f.format(o);
  }
  ADD_FAILURE() << name << " is not declared";
  return {};
}

// Every value of an enum that is both an option and a written result: the
// option takes the text the files carry, gives it back when formatted, and
// the read-back parser turns that text into the same value; a text outside
// the list is refused naming exactly the values written.
template <class E, std::size_t N, class Get, class Parse>
void expect_one_text_per_value(std::string_view option, const E (&values)[N], std::string_view column, Get get,
                               Parse parse) {
  std::string listed;
  for (const E v : values) {
    const std::string text(awcc::to_string(v));
    const std::vector<OptionSetting> call{{std::string(option), text, ""}};
    const auto o = awcc::process_options(call);
    EXPECT_EQ(get(o), v) << option << " = " << text;
    const auto written = formatted(awcc::awcc_option_fields(), option, o.awcc_options);
    EXPECT_EQ(written, text) << option;
    EXPECT_EQ(parse(written, awcc::WrittenAt{"f.json", "/0", option}), v) << option;
    listed += (listed.empty() ? "" : " | ") + text;
  }
  if (!column.empty()) {
    std::string from_column;
    for (const auto t : awcc::written_values(column)) from_column += (from_column.empty() ? "" : " | ") + std::string(t);
    EXPECT_EQ(from_column, listed) << column;
  }
  const std::vector<OptionSetting> bad{{std::string(option), "sideways", ""}};
  EXPECT_EQ(std::string(error_of(bad).what()), std::string(option) + ": 'sideways' is not one of " + listed);
}

}  // namespace

TEST(ProcessOptions, AnEnumOptionIsSpelledAsTheFilesWriteItAndReadItBack) {
  namespace column = awcc::profile_column;
  expect_one_text_per_value("weighting", awcc::values::weighting, column::awcc_weighting,
                            [](const ProcessOptions& o) { return o.awcc_options.weighting; }, awcc::parse_weighting);
  expect_one_text_per_value("correlate", awcc::values::signal, column::awcc_signal,
                            [](const ProcessOptions& o) { return o.awcc_options.signal; },
                            awcc::parse_correlation_signal);
  expect_one_text_per_value("subsample", awcc::values::subsample, column::awcc_subsample,
                            [](const ProcessOptions& o) { return o.awcc_options.subsample; }, awcc::parse_subsample);
}

TEST(ProcessOptions, AThresholdRuleAndAProbeAreSpelledAsTheJsonWritesThem) {
  for (const auto rule : awcc::values::threshold_rule) {
    if (rule == awcc::ThresholdRule::hysteresis) continue;  // its threshold is a pair, checked elsewhere
    const std::vector<OptionSetting> call{{"threshold-rule", std::string(awcc::to_string(rule)), ""},
                                          {"threshold", rule == awcc::ThresholdRule::fixed ? "2.5V" : "0.5", ""}};
    const auto o = awcc::process_options(call);
    EXPECT_EQ(o.binarisation.rule, rule);
    EXPECT_EQ(formatted(awcc::binarisation_option_fields(), "threshold-rule", o.binarisation),
              awcc::to_string(rule));
  }
  for (const auto probe : awcc::values::probe) {
    const std::vector<OptionSetting> call{{"probe", std::string(awcc::to_string(probe)), ""}};
    const auto o = awcc::process_options(call);
    EXPECT_EQ(o.binarisation.probe, probe);
    EXPECT_EQ(formatted(awcc::binarisation_option_fields(), "probe", o.binarisation), awcc::to_string(probe));
  }
}

TEST(ProcessOptions, ASwitchIsWrittenOnOrOffAndTakesItsAliases) {
  for (const bool on : {true, false}) {
    const std::string written(awcc::switch_text(on));
    const auto aliases = on ? std::vector<std::string>{written, "true", "yes", "1"}
                            : std::vector<std::string>{written, "false", "no", "0"};
    for (const auto& text : aliases) {
      const std::vector<OptionSetting> call{{"roc", text, ""}};
      const auto o = awcc::process_options(call);
      EXPECT_EQ(o.awcc_options.roc, on) << text;
      // Formatted as the profile CSV writes it, whatever alias was given.
      EXPECT_EQ(formatted(awcc::awcc_option_fields(), "roc", o.awcc_options), written) << text;
      EXPECT_EQ(awcc::parse_switch(written, awcc::WrittenAt{"f.csv", "line 2", "awcc_roc"}), on);
    }
  }
  const std::vector<OptionSetting> bad{{"roc", "maybe", ""}};
  EXPECT_EQ(std::string(error_of(bad).what()), "roc: 'maybe' is not on or off");
}

TEST(ProcessOptions, TheMethodNamesEachCombinationAndReadsItBack) {
  // Every combination of the fields is written so that it reads back the same.
  for (const bool fscc : {false, true}) {
    for (const bool awcc : {false, true}) {
      for (const bool events : {false, true}) {
        for (const auto multi : {awcc::MultiTipChoice::automatic, awcc::MultiTipChoice::off, awcc::MultiTipChoice::on}) {
          awcc::ProcessOptions o;
          o.fscc = fscc;
          o.awcc = awcc;
          o.events = events;
          o.multi_tip = multi;
          const auto fields = awcc::process_option_fields();
          const auto field = std::find_if(fields.begin(), fields.end(),
                                           [](const auto& f) { return f.name == "method"; });
          const std::string text = field->format(o);
          awcc::ProcessOptions back;
          field->parse(back, text);
          EXPECT_EQ(back.fscc, fscc) << text;
          EXPECT_EQ(back.awcc, awcc) << text;
          EXPECT_EQ(back.events, events) << text;
          EXPECT_EQ(back.multi_tip, multi) << text;
        }
      }
    }
  }
  // The names a user types: auto is the default; events and multi-tip run FSCC and AWCC beside them.
  EXPECT_EQ(awcc::process_options({}).multi_tip, awcc::MultiTipChoice::automatic);
  const auto events = awcc::process_options(std::vector<awcc::OptionSetting>{{"method", "events", ""}});
  EXPECT_TRUE(events.events && events.fscc && events.awcc);
  EXPECT_EQ(events.multi_tip, awcc::MultiTipChoice::off);
  const auto fewer = awcc::process_options(std::vector<awcc::OptionSetting>{{"method", "fscc+multi-tip", ""}});
  EXPECT_TRUE(fewer.fscc && !fewer.awcc && fewer.multi_tip == awcc::MultiTipChoice::on);
  EXPECT_THROW((void)awcc::process_options(std::vector<awcc::OptionSetting>{{"method", "fscc+awcc", ""}}),
               awcc::OptionError);
}

TEST(ProfileFlowOptions, EachDeclaredDefaultReadsBackAndADischargeNeedsItsUnit) {
  const awcc::ProfileFlowOptions defaults;
  for (const auto& f : awcc::profile_flow_option_fields()) {
    awcc::ProfileFlowOptions o;
    f.parse(o, f.format(defaults));
    EXPECT_EQ(f.format(o), f.format(defaults)) << f.name;
  }
  const auto o = awcc::profile_flow_options(std::vector<awcc::OptionSetting>{
      {"discharge", "150l/s/m", ""}, {"invert", "zero", ""}, {"depth-levels", "0.5,0.8", ""}});
  ASSERT_TRUE(o.discharge);
  EXPECT_DOUBLE_EQ(*o.discharge, 0.15);
  EXPECT_EQ(o.invert, awcc::InvertRule::zero);
  EXPECT_EQ(o.levels, (std::vector<double>{0.5, 0.8}));
  try {
    (void)awcc::profile_flow_options(std::vector<awcc::OptionSetting>{{"discharge", "0.2", ""}});
    ADD_FAILURE() << "a discharge without a unit was accepted";
  } catch (const awcc::OptionError& e) {
    EXPECT_EQ(e.quantity(), "discharge");
  }
  // The chute angle: degrees or radians as written, none by default; a bare
  // 30 (degrees or radians?) is refused naming the option.
  EXPECT_FALSE(awcc::ProfileFlowOptions{}.chute_angle);
  for (const auto& [text, radians] : {std::pair{"30deg", 30.0 * std::numbers::pi / 180.0}, {"0.5rad", 0.5}}) {
    const auto a = awcc::profile_flow_options(std::vector<awcc::OptionSetting>{{"chute-angle", text, ""}});
    ASSERT_TRUE(a.chute_angle) << text;
    EXPECT_NEAR(*a.chute_angle, radians, 1e-15) << text;
  }
  try {
    (void)awcc::profile_flow_options(std::vector<awcc::OptionSetting>{{"chute-angle", "30", ""}});
    ADD_FAILURE() << "a chute angle without a unit was accepted";
  } catch (const awcc::OptionError& e) {
    EXPECT_EQ(e.quantity(), "chute-angle");
    EXPECT_NE(std::string(e.what()).find("deg"), std::string::npos) << e.what();
  }
}
