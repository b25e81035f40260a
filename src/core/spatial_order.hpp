// Spatial numbering of grains: an order along a Morton (Z-order) curve, so that grains near each
// other in space are near each other in memory (and on the same thread in the cycle's loops).
#pragma once

#include "core/types.hpp"

#include <cstddef>
#include <vector>

namespace rocklab {

/// The order that numbers points along a Morton curve of cubic cells of size `cell` [m] counted
/// from `lo` [m]: order[k] is the index of the point that goes to place k. Ties keep their order.
std::vector<std::size_t> morton_order(const std::vector<Vec3>& x, int dim, double cell,
                                      const Vec3& lo);

/// morton_order from the points' own lower corner.
std::vector<std::size_t> morton_order(const std::vector<Vec3>& x, int dim, double cell);

} // namespace rocklab
