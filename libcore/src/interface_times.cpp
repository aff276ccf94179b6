#include "awcc/interface_times.hpp"

namespace awcc {

std::vector<Crossing> crossings(const AirIntervals& tip) {
  std::vector<Crossing> out;
  if (!(tip.fs > 0.0)) return out;
  out.reserve(tip.intervals.size());
  const double period = 1.0 / tip.fs;
  for (const AirInterval& interval : tip.intervals) {
    Crossing crossing;
    crossing.front = (static_cast<double>(interval.start) - 0.5) * period;
    crossing.rear = (static_cast<double>(interval.stop) - 0.5) * period;
    crossing.censored = interval.start <= 0 || interval.stop >= tip.sample_count;
    out.push_back(crossing);
  }
  return out;
}

}  // namespace awcc
