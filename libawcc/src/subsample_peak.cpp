#include "awcc/subsample_peak.hpp"

#include <algorithm>
#include <cmath>

namespace awcc {

std::string_view to_string(Subsample subsample) {
  switch (subsample) {
    case Subsample::none: return "none";
    case Subsample::parabolic: return "parabolic";
    case Subsample::gaussian: return "gaussian";
    case Subsample::triangle: return "triangle";
    case Subsample::centroid: return "centroid";
  }
  return "none";
}

namespace detail {

double parabolic_offset(double minus, double centre, double plus) {
  const double curvature = minus - 2 * centre + plus;
  return curvature < 0.0 ? 0.5 * (minus - plus) / curvature : 0.0;
}

double gaussian_offset(double minus, double centre, double plus) {
  if (!(minus > 0.0 && centre > 0.0 && plus > 0.0)) return parabolic_offset(minus, centre, plus);
  return parabolic_offset(std::log(minus), std::log(centre), std::log(plus));
}

double triangle_offset(double minus, double centre, double plus) {
  const double drop = centre - std::min(minus, plus);
  return drop > 0.0 ? (plus - minus) / (2 * drop) : 0.0;
}

}  // namespace detail

double subsample_offset(Subsample method, const CorrelationAt& r, std::int64_t peak, std::int64_t first,
                        std::int64_t last) {
  if (method == Subsample::none || peak <= first || peak >= last) return 0.0;
  const double centre = r(peak);
  switch (method) {
    case Subsample::none: return 0.0;
    case Subsample::parabolic: return detail::parabolic_offset(r(peak - 1), centre, r(peak + 1));
    case Subsample::gaussian: return detail::gaussian_offset(r(peak - 1), centre, r(peak + 1));
    case Subsample::triangle: return detail::triangle_offset(r(peak - 1), centre, r(peak + 1));
    case Subsample::centroid: {
      if (!(centre > 0.0)) return 0.0;
      const double half = 0.5 * centre;
      double weight = centre - half, moment = 0.0;
      for (std::int64_t k = peak - 1; k >= first; --k) {
        const double w = r(k) - half;
        if (!(w > 0.0)) break;
        weight += w;
        moment += w * static_cast<double>(k - peak);
      }
      for (std::int64_t k = peak + 1; k <= last; ++k) {
        const double w = r(k) - half;
        if (!(w > 0.0)) break;
        weight += w;
        moment += w * static_cast<double>(k - peak);
      }
      return moment / weight;
    }
  }
  return 0.0;
}

}  // namespace awcc
