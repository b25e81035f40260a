// Thinning of dense polylines for pictures: a stress-strain curve of a 10k-grain test has ~40k
// samples per series, hundreds per pixel column of the plot. Units: whatever the points are in
// (the plots pass SVG pixels).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace rocklab {

/// The indices (ascending, first and last included) of the points a polyline keeps when every
/// dropped point lies within `tolerance` of the segment between the kept points around it
/// (Douglas-Peucker, iterative). Non-finite points are not allowed.
std::vector<std::size_t> thin_polyline(const std::vector<std::array<double, 2>>& points,
                                       double tolerance);

} // namespace rocklab
