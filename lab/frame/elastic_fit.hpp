// Elastic constants from a loading branch of the frame's samples. Units SI.
#pragma once

#include "lab/frame/loading_frame.hpp"

#include <vector>

namespace rocklab {

/// Tangent slope of load vs axial strain by least squares over the pre-peak samples with
/// lo x peak <= load <= hi x peak, and -d(lateral)/d(axial) over the same window.
struct ElasticFit {
  double youngs_modulus = 0, poisson_ratio = 0;
  std::size_t points = 0;
};
ElasticFit fit_elastic(const std::vector<LabSample>& s, double peak, double lo, double hi);

} // namespace rocklab
