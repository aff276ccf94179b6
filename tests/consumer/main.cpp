// A downstream program built against the installed package: it synthesises a
// short scene (synth::synth), reads samples through a recording (awcc::io),
// processes it (awcc::awcc), trains a small
// correction model on synthetic runs, saves it, loads it back and corrects a
// measurement (correction::correction), runs the same scene as a study
// (awcc::study), and checks a property of each step so that linking alone is
// not mistaken for success.
#include <awcc/awcc.hpp>
#include <awcc/recording.hpp>
#include <awcc/units.hpp>
#include <awcc/version.hpp>
#include <correction/model.hpp>
#include <correction/training.hpp>
#include <cstdio>
#include <filesystem>
#include <study/run.hpp>
#include <synth/synthesiser.hpp>
#include <vector>

int main(int argc, char** argv) {
  const std::filesystem::path scratch = argc > 1 ? argv[1] : ".";
  synth::Scene scene;
  scene.duration = awcc::parse_quantity("2s", awcc::Dimension::time);
  scene.fs = awcc::parse_quantity("100kHz", awcc::Dimension::frequency);
  const auto result = synth::synthesise(scene);
  const double c = result.signals.at(0).void_fraction();
  const auto a = awcc::awcc(result.signals[0], result.signals[1], scene.streamwise_separation());
  const bool awcc_ok = a.ok() && a.velocity > 5.0 && a.velocity < 15.0;
  // The study synthesises the same record and processes it as pdp process: the same AWCC.
  const auto run = study::run_scene(scene, {});
  const bool study_ok = run.processed.awcc && run.processed.awcc->ok() && run.processed.awcc->velocity == a.velocity &&
                        run.measurement.measurement.velocity == a.velocity;

  // awcc::io: two channels of frames handed back interleaved as given.
  const auto recording = awcc::memory_recording(std::vector<float>{0.25f, 4.0f, 0.5f, 3.5f}, 2, 1000.0);
  std::vector<float> frames(4, 0.0f);
  const bool io_ok = recording->read(frames, 2) == 2 && frames[1] == 4.0f && frames[2] == 0.5f &&
                     recording->info().format == "array";

  // Training rows: truth = 0.9 x measured, Tu truth = measured + 0.05.
  std::vector<correction::TrainingRow> rows;
  for (int i = 0; i < 60; ++i) {
    correction::Measurement m;
    m.velocity = 2.0 + 0.1 * i;
    m.turbulence_intensity = 0.1 + 0.002 * i;
    m.void_fraction = 0.1 + 0.001 * i;
    m.bubble_count_rate = 500.0;
    m.dx = 5e-3;
    m.dy = 1e-3;
    m.np = 10;
    m.windows_accepted = 200;
    correction::TrainingRow r;
    r.run = i;
    r.features = correction::make_features(m).features;
    r.true_velocity = 0.9 * *m.velocity;
    r.true_turbulence_intensity = *m.turbulence_intensity + 0.05;
    rows.push_back(r);
  }
  correction::ForestOptions o;
  o.trees = 5;
  const auto model = correction::fit_model(rows, correction::TargetForm::ratio, correction::TargetForm::difference, o,
                                           o, 100);
  const auto path = scratch / "consumer.qrf";
  model.save(path);
  const auto loaded = correction::CorrectionModel::load(path);
  correction::Measurement m;
  m.velocity = 4.0;
  m.turbulence_intensity = 0.15;
  m.void_fraction = 0.12;
  m.bubble_count_rate = 500.0;
  m.dx = 5e-3;
  m.dy = 1e-3;
  m.np = 10;
  m.windows_accepted = 300;
  const auto corrected = loaded.correct(m);
  const bool correction_ok = corrected.corrected() && std::abs(corrected.velocity->median() - 3.6) < 1e-9 &&
                             std::abs(corrected.turbulence_intensity->median() - 0.2) < 1e-9;
  std::printf("awcc %s: void fraction %.3f, AWCC %.3f m/s (%s), corrected velocity %.3f m/s (%s), recording read (%s), "
              "study (%s)\n",
              awcc::version, c, a.velocity, awcc_ok ? "ok" : "wrong",
              corrected.velocity ? corrected.velocity->median() : 0.0, correction_ok ? "ok" : "wrong",
              io_ok ? "ok" : "wrong", study_ok ? "ok" : "wrong");
  return (c > 0.0 && c < 1.0 && awcc_ok && correction_ok && io_ok && study_ok) ? 0 : 1;
}
