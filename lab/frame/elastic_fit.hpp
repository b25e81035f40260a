// Elastic constants from a loading branch of the frame's samples. Units SI.
#pragma once

#include "lab/frame/loading_frame.hpp"

#include <vector>

namespace rocklab {

/// Slope of load vs axial strain by least squares, -d(lateral)/d(axial) over the same samples,
/// and the coefficient of determination of the load fit.
struct ElasticFit {
  double youngs_modulus = 0, poisson_ratio = 0, r2 = 0;
  std::size_t points = 0;
};

/// The fit over the samples with lo <= load <= hi [Pa], in the order given.
ElasticFit fit_window(const std::vector<LabSample>& s, double lo, double hi);

/// The fit over the pre-peak samples with lo x peak <= load <= hi x peak.
ElasticFit fit_elastic(const std::vector<LabSample>& s, double peak, double lo, double hi);

} // namespace rocklab
