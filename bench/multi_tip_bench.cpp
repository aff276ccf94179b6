// Benchmark of multi-tip processing on the four-tip base case
// (docs/performance.md, issue 30).
//
//   multi_tip_bench [--duration SECONDS] [--repeat N]
//
// Synthesises the base case (synth::Scene's defaults: 10 m/s, c = 0.25,
// 3 mm spheres, 500 kHz) with the four tips of samples/four-tip.toml into
// memory once, then times on one thread the chain a record goes through:
// the crossings of every tip, FSCC of the tip pair (pair_probe's first
// velocity), pair_probe (the joint pairing of the trailing tips), and
// multi_tip with each velocity algorithm.
// Median of N runs of each step and of the whole chain, and the cost per
// leading bubble.
#include <cstdio>
#include <string>
#include <vector>

#include "awcc/fscc.hpp"
#include "awcc/interface_times.hpp"
#include "awcc/multi_tip.hpp"
#include "bench_util.hpp"
#include "synth/synthesiser.hpp"

using bench::now;

int main(int argc, char** argv) {
  const auto args = bench::base_case_args(argc, argv);
  synth::Scene scene;
  scene.duration = args.duration;
  scene.tips = {{0, 0, 0}, {5e-3, 0, 0}, {5e-3, 1.5e-3, 0}, {5e-3, 0, 1.5e-3}};  // samples/four-tip.toml
  const double t_synth = now();
  const auto syn = synth::synthesise(scene);
  std::printf("four-tip base case %.0f s at %.0f kHz (synthesised in %.1f s): air intervals per tip", args.duration,
              scene.fs / 1e3, now() - t_synth);
  for (const auto& s : syn.signals) std::printf(" %zu", s.intervals.size());
  std::printf("\n");
  std::vector<awcc::Vec3> positions;
  for (const auto& t : scene.probe_tips()) positions.push_back({t.x, t.y, t.z});
  const awcc::ProbeGeometry geometry(positions);

  std::vector<std::vector<awcc::Crossing>> tips;
  const double t_cross = bench::median_seconds(args.repeat, [&] {
    tips.clear();
    for (const auto& s : syn.signals) tips.push_back(awcc::crossings(s));
  });
  const double dx = scene.tips[1].x - scene.tips[0].x;
  awcc::FsccResult first;
  const double t_fscc =
      bench::median_seconds(args.repeat, [&] { first = awcc::fscc(syn.signals[0], syn.signals[1], dx); });
  std::printf("FSCC of the tip pair: %.3f s, %.3f m/s\n", t_fscc, first.velocity);
  awcc::ProbePairing pairing;
  const double t_pair =
      bench::median_seconds(args.repeat, [&] { pairing = awcc::pair_probe(geometry, tips, {}, first.velocity); });
  const double bubbles = static_cast<double>(pairing.bubbles.size());
  const auto per = [&](double seconds) { return seconds / bubbles * 1e9; };
  std::printf("crossings of 4 tips: %.3f s; pair_probe: %.3f s (%.0f ns a leading bubble, %zu of them)\n", t_cross,
              t_pair, per(t_pair), pairing.bubbles.size());
  for (auto algorithm : awcc::velocity_algorithms) {
    awcc::MultiTipResult r;
    const awcc::MultiTipOptions o{.algorithm = algorithm};
    const double t_solve =
        bench::median_seconds(args.repeat, [&] { r = awcc::multi_tip(geometry, pairing.bubbles, args.duration, o); });
    // The whole chain once more end to end, as a record meets it.
    const double t_chain = bench::median_seconds(args.repeat, [&] {
      std::vector<std::vector<awcc::Crossing>> c;
      for (const auto& s : syn.signals) c.push_back(awcc::crossings(s));
      const auto f = awcc::fscc(syn.signals[0], syn.signals[1], dx);
      const auto p = awcc::pair_probe(geometry, c, {}, f.velocity);
      r = awcc::multi_tip(geometry, p.bubbles, args.duration, o);
    });
    std::printf("multi_tip %s: %.3f s (%.0f ns a bubble); chain %.3f s (%.0f ns a bubble), %lld accepted; peak %.0f MB\n",
                std::string(awcc::to_string(algorithm)).c_str(), t_solve, per(t_solve), t_chain, per(t_chain),
                static_cast<long long>(r.bubbles_accepted), bench::peak_mb());
    if (!r.caution.empty()) std::printf("  caution: %s\n", r.caution.c_str());
  }
  return 0;
}
