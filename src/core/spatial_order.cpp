// Morton (Z-order) numbering of points (spatial_order.hpp).
#include "core/spatial_order.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>

namespace rocklab {

std::vector<std::size_t> morton_order(const std::vector<Vec3>& x, int dim, double cell,
                                      const Vec3& lo) {
  auto spread = [](std::uint64_t v) { // 21 bits -> every third bit
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  std::vector<std::pair<std::uint64_t, std::size_t>> keys(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    std::uint64_t key = 0;
    for (int d = 0; d < dim; ++d)
      key |= spread(static_cast<std::uint64_t>(std::max(0.0, (x[i][d] - lo[d]) / cell))) << d;
    keys[i] = {key, i};
  }
  std::stable_sort(keys.begin(), keys.end());
  std::vector<std::size_t> order(x.size());
  for (std::size_t k = 0; k < keys.size(); ++k)
    order[k] = keys[k].second;
  return order;
}

std::vector<std::size_t> morton_order(const std::vector<Vec3>& x, int dim, double cell) {
  Vec3 lo = Vec3::Zero();
  if (!x.empty()) {
    lo = x[0];
    for (const Vec3& p : x)
      lo = lo.cwiseMin(p);
  }
  return morton_order(x, dim, cell, lo);
}

} // namespace rocklab
