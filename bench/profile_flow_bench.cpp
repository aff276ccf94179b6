// Benchmark of the profile quantities (awcc/profile_flow.hpp; docs/performance.md, issue 31).
//
//   profile_flow_bench [--repeat N]
//
// A ten-row stepped-chute profile (D_0 = 0.3, Y90 = 0.1 m, nine rows from
// 0.1 to 1.0 Y90 and one at 1.2 Y90 with c = 0.97 (the model is for y <= Y90), u = 3 (y / Y90)^(1/6) m/s, c +/- 0.02, u +/- 2 %): the time of
// profile_flow without draws and with 1,000 Monte Carlo draws (the default),
// median of N runs, on one thread. Issue 31 asks for under 0.2 s added by the
// draws to a ten-file profile.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "awcc/profile_flow.hpp"
#include "bench_util.hpp"

int main(int argc, char** argv) {
  int repeat = 5;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeat") && i + 1 < argc) repeat = std::atoi(argv[++i]);
  }
  const double y90 = 0.1;
  const awcc::ConcentrationModel model{awcc::ConcentrationModelKind::stepped_chute, 0.3, y90};
  std::vector<awcc::ProfileRow> rows;
  for (int i = 0; i < 10; ++i) {
    awcc::ProfileRow r;
    r.name = "position " + std::to_string(i + 1);
    r.y = i < 9 ? y90 * (0.1 + 0.9 * i / 8.0) : 1.2 * y90;
    r.c = i < 9 ? model(r.y) : 0.97;
    r.c_ci95 = {r.c - 0.02, r.c + 0.02};
    r.bubble_frequency = 150.0;
    r.bubble_frequency_ci95 = {140.0, 160.0};
    r.u = 3.0 * std::pow(r.y / y90, 1.0 / 6.0);
    r.u_ci95 = awcc::Interval95{*r.u * 0.98, *r.u * 1.02};
    rows.push_back(r);
  }
  awcc::ProfileFlowOptions none;
  none.draws = 0;
  awcc::ProfileFlowResult result;
  const double t0 = bench::median_seconds(repeat, [&] { result = awcc::profile_flow(rows, none); });
  const double t1 = bench::median_seconds(repeat, [&] { result = awcc::profile_flow(rows, {}); });
  std::printf("ten-row profile: %.3f ms without draws, %.1f ms with %d draws (%.1f us a draw)\n", 1e3 * t0, 1e3 * t1,
              result.draws, 1e6 * (t1 - t0) / result.draws);
  std::printf("%s", result.report().c_str());
  return 0;
}
