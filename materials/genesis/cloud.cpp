// Genesis stage "cloud": grain radii from the card's size distribution filling (1 - n) of the
// vessel, placed at random in the vessel enlarged to the cloud porosity (boundary contraction) or
// shrunk inside it (grain scaling), and numbered along a Morton curve.
#include "core/spatial_order.hpp"
#include "materials/genesis/stages.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace rocklab::genesis {

namespace {

std::vector<double> sample_radii(const MaterialCard& c, double grain_volume_target,
                                 std::mt19937_64& rng) {
  std::vector<double> r;
  double vol = 0;
  while (vol < grain_volume_target) {
    double radius;
    if (c.sieve.empty()) {
      radius = c.r_min + (c.r_max - c.r_min) * uniform01(rng);
    } else {
      // Diameter drawn by mass from the sieve curve, then thinned by (d_min/d)^dim so the
      // number of grains per size follows the mass fractions.
      for (;;) {
        const double u = uniform01(rng);
        std::size_t k = 1;
        while (k + 1 < c.sieve.size() && c.sieve[k].second < u)
          ++k;
        const auto [d0, f0] = c.sieve[k - 1];
        const auto [d1, f1] = c.sieve[k];
        const double d = f1 > f0 ? d0 + (d1 - d0) * (u - f0) / (f1 - f0) : d1;
        if (uniform01(rng) <= std::pow(c.sieve.front().first / d, c.dim)) {
          radius = 0.5 * d;
          break;
        }
      }
    }
    r.push_back(radius);
    vol += grain_volume(c.dim, radius);
  }
  // Scale so the grains fill exactly (1 - n) of the vessel.
  const double f = std::pow(grain_volume_target / vol, 1.0 / c.dim);
  for (double& x : r)
    x *= f;
  return r;
}

} // namespace

void place_grains(Run& g) {
  Model& m = g.m;
  const MaterialCard& card = g.card;
  const int dim = card.dim;
  std::mt19937_64& rng = g.rng;
  const double V0 = card.vessel.volume(dim);
  std::vector<double> radii = sample_radii(card, (1 - card.porosity) * V0, rng);
  const double r_avg = [&] {
    double s = 0;
    for (double r : radii)
      s += r;
    return s / static_cast<double>(radii.size());
  }();
  // The cloud is at the cloud porosity: boundary contraction puts the full-size grains into a
  // vessel enlarged by 1/shrink; grain scaling shrinks the grains by `shrink` inside the vessel.
  const double shrink = std::pow((1 - card.cloud_porosity) / (1 - card.porosity), 1.0 / dim);
  const bool contraction = card.packing_method == MaterialCard::Packing::Contraction;
  const double vessel_scale = contraction ? 1.0 / shrink : 1.0;
  const double grain_scale = contraction ? 1.0 : shrink;
  Vessel vessel = make_vessel(m, card, vessel_scale);
  const int grains = m.group_index("grains");
  const bool round = card.vessel.shape == SpecimenShape::Disk2D ||
                     card.vessel.shape == SpecimenShape::Cylinder ||
                     card.vessel.shape == SpecimenShape::Disk3D;
  const Vec3& L = card.vessel.size;
  const Vec3 half =
      vessel_scale * (round ? Vec3(0.5 * L.x(), 0.5 * L.x(), dim == 3 ? 0.5 * L.y() : 0.0)
                            : Vec3(0.5 * L.x(), 0.5 * L.y(), dim == 3 ? 0.5 * L.z() : 0.0));
  std::vector<Vec3> cloud;
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double r = radii[i] * grain_scale;
    // Uniform in the shape's bounding box, kept when the grain lies inside the shape.
    Vec3 x = Vec3::Zero();
    for (int attempt = 0;; ++attempt) {
      for (int d = 0; d < dim; ++d)
        x[d] = (2 * uniform01(rng) - 1) * half[d];
      if (card.vessel.contains(x / vessel_scale, r / vessel_scale) || attempt > 10000)
        break;
    }
    cloud.push_back(x);
  }
  // Number the grains along a Morton curve (the random cloud order made the contact loop and the
  // force sum ~2x slower on big specimens).
  {
    const std::vector<std::size_t> order = morton_order(cloud, dim, 2 * r_avg * grain_scale, -half);
    std::vector<double> sorted_radii(radii.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      const std::size_t i = order[k];
      sorted_radii[k] = radii[i];
      m.balls.add(dim, static_cast<std::int64_t>(k + 1), cloud[i], radii[i] * grain_scale,
                  card.density, grains);
    }
    radii = std::move(sorted_radii);
  }
  g.radii = std::move(radii);
  g.r_avg = r_avg;
  g.contraction = contraction;
  g.vessel_scale = vessel_scale;
  g.grain_scale = grain_scale;
  g.vessel = std::move(vessel);
}

} // namespace rocklab::genesis
