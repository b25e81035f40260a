#include "core/walls.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rocklab {

Wall plane_wall(int dim, const std::string& name, const Vec3& p, const Vec3& n, double extent,
                const std::optional<Vec3>& edge) {
  Wall w;
  w.name = name;
  const double h = 0.5 * extent;
  Facet f;
  if (dim == 2) {
    const Vec3 u(-n.y(), n.x(), 0);
    f.nv = 2;
    f.v[0] = p - h * u;
    f.v[1] = p + h * u;
    w.facets.push_back(f);
  } else {
    Vec3 u;
    if (edge) {
      u = *edge;
    } else {
      const Vec3 g = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
      u = (g - g.dot(n) * n).normalized();
    }
    const Vec3 v = n.cross(u);
    const Vec3 a = p - h * u - h * v, b = p + h * u - h * v, c = p + h * u + h * v,
               d = p - h * u + h * v;
    f.v = {a, b, c};
    w.facets.push_back(f);
    f.v = {a, c, d};
    w.facets.push_back(f);
  }
  w.center = p;
  w.update_bounds();
  return w;
}

void Wall::update_bounds() {
  if (is_cylinder()) {
    // Conservative box: the radius plus the axial reach in every direction.
    const double reach = cylinder_radius + (half_height > 0 ? half_height : 1e300);
    lo = center - Vec3::Constant(reach);
    hi = center + Vec3::Constant(reach);
    return;
  }
  lo = Vec3::Constant(1e300);
  hi = Vec3::Constant(-1e300);
  for (const Facet& f : facets)
    for (int k = 0; k < f.nv; ++k) {
      lo = lo.cwiseMin(f.v[k]);
      hi = hi.cwiseMax(f.v[k]);
    }
}

void Wall::move(double dt) {
  const Vec3 dx = velocity * dt;
  const Vec3 phi = spin * dt;
  const bool rotates = phi.squaredNorm() > 0;
  if (is_cylinder()) {
    cylinder_radius = std::max(cylinder_radius + radial_velocity * dt, 1e-300);
    if (rotates)
      axis = rotate_by(axis, phi).normalized();
    center += dx;
    update_bounds();
    return;
  }
  for (Facet& f : facets)
    for (int k = 0; k < f.nv; ++k) {
      if (radial_velocity != 0)
        f.v[k] += radial_velocity * dt * radial_dir(f.v[k]);
      f.v[k] = rotates ? (center + rotate_by(f.v[k] - center, phi) + dx) : Vec3(f.v[k] + dx);
    }
  center += dx;
  update_bounds();
}

double Wall::max_vertex_speed() const {
  double vmax = 0;
  const double w = spin.norm();
  if (is_cylinder())
    return velocity.norm() + std::abs(radial_velocity) +
           w * (cylinder_radius + std::max(half_height, 0.0));
  for (const Facet& f : facets)
    for (int k = 0; k < f.nv; ++k)
      vmax = std::max(vmax,
                      velocity.norm() + w * (f.v[k] - center).norm() + std::abs(radial_velocity));
  return vmax;
}

namespace {
Vec3 closest_on_segment(const Vec3& a, const Vec3& b, const Vec3& p) {
  const Vec3 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 <= 0)
    return a;
  const double u = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return a + u * ab;
}

// Closest point on triangle abc to p, by Voronoi-region classification.
Vec3 closest_on_triangle(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0)
    return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3)
    return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
    return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6)
    return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
    return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}
} // namespace

Vec3 Wall::closest_point(const Vec3& p, std::int32_t* facet) const {
  if (is_cylinder()) {
    if (facet)
      *facet = 0;
    const Vec3 r = p - center;
    double a = r.dot(axis);
    Vec3 radial = r - a * axis;
    const double len = radial.norm();
    // On the axis every direction is equally near; pick one that does not depend on p.
    radial = len > 0 ? Vec3(radial / len) : Vec3(axis.unitOrthogonal());
    if (half_height > 0)
      a = std::clamp(a, -half_height, half_height);
    return center + a * axis + cylinder_radius * radial;
  }
  double dmin = std::numeric_limits<double>::max();
  Vec3 best = p;
  for (std::size_t f = 0; f < facets.size(); ++f) {
    const Vec3 q = closest_point_on_facet(facets[f], p);
    const double d = (q - p).squaredNorm();
    if (d < dmin) {
      dmin = d;
      best = q;
      if (facet)
        *facet = static_cast<std::int32_t>(f);
    }
  }
  return best;
}

Vec3 closest_point_on_facet(const Facet& f, const Vec3& p) {
  if (f.nv == 2)
    return closest_on_segment(f.v[0], f.v[1], p);
  return closest_on_triangle(f.v[0], f.v[1], f.v[2], p);
}

} // namespace rocklab
