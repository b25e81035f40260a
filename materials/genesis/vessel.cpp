// The genesis vessel: planar and round walls around the specimen shape, servo-controlled to a
// stress (the servo law is core/servo.hpp's).
#include "materials/genesis/stages.hpp"

#include "core/servo.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab::genesis {

namespace {

constexpr double kPi = std::numbers::pi;

// A circular (2D) or cylindrical (3D, axis z, unbounded along it) wall of radius r.
Wall round_wall(double r) {
  Wall w;
  w.name = "vessel.lateral";
  w.cylinder_radius = r;
  w.half_height = 0;
  w.center = Vec3::Zero();
  w.axis = Vec3::UnitZ();
  w.update_bounds();
  return w;
}

} // namespace

double Vessel::extent(const Model& m, int axis) const {
  double lo = 0, hi = 0;
  for (const Servo& s : servos)
    if (!s.radial && std::abs(s.n_in[axis]) > 0.5) {
      const double c = m.walls[s.wall].center[axis];
      (s.n_in[axis] > 0 ? lo : hi) = c;
    }
  return hi - lo;
}

double Vessel::lateral_radius(const Model& m) const {
  for (const Servo& s : servos)
    if (s.radial)
      return radius(m, s);
  return 0;
}

double Vessel::volume(const Model& m) const {
  switch (shape) {
  case SpecimenShape::Rectangle:
    return extent(m, 0) * extent(m, 1);
  case SpecimenShape::Prism:
    return extent(m, 0) * extent(m, 1) * extent(m, 2);
  case SpecimenShape::Disk2D: {
    const double r = lateral_radius(m);
    return kPi * r * r;
  }
  default: {
    const double r = lateral_radius(m);
    return kPi * r * r * extent(m, 2);
  }
  }
}

double Vessel::area(const Model& m, const Servo& s) const {
  if (s.radial) {
    const double r = radius(m, s);
    return 2 * kPi * r * (dim == 2 ? 1.0 : extent(m, 2));
  }
  const int axis = std::abs(s.n_in.x()) > 0.5 ? 0 : (std::abs(s.n_in.y()) > 0.5 ? 1 : 2);
  if (shape == SpecimenShape::Cylinder || shape == SpecimenShape::Disk3D) {
    const double r = lateral_radius(m);
    return kPi * r * r;
  }
  double a = 1;
  for (int d = 0; d < dim; ++d)
    if (d != axis)
      a *= extent(m, d);
  return a;
}

double Vessel::half_extent(const Model& m, const Servo& s) const {
  return s.radial ? radius(m, s) : std::abs(m.walls[s.wall].center.dot(s.n_in));
}

double Vessel::stress(const Model& m, const Servo& s) const {
  const Wall& w = m.walls[s.wall];
  const double f = s.radial ? w.radial_force : -w.force.dot(s.n_in);
  return f / area(m, s);
}

ShapeSpec Vessel::shape_now(const Model& m) const {
  ShapeSpec s;
  s.shape = shape;
  switch (shape) {
  case SpecimenShape::Rectangle:
    s.size = Vec3(extent(m, 0), extent(m, 1), 0);
    break;
  case SpecimenShape::Prism:
    s.size = Vec3(extent(m, 0), extent(m, 1), extent(m, 2));
    break;
  case SpecimenShape::Disk2D:
    s.size = Vec3(2 * lateral_radius(m), 0, 0);
    break;
  case SpecimenShape::Cylinder:
  case SpecimenShape::Disk3D:
    s.size = Vec3(2 * lateral_radius(m), extent(m, 2), 0);
    break;
  }
  return s;
}

bool Vessel::holds(const Model& m, const Vec3& x) const {
  for (const Servo& s : servos) {
    const Wall& w = m.walls[s.wall];
    if (s.radial) {
      Vec3 r = x - w.center;
      r -= r.dot(w.axis) * w.axis;
      if (r.norm() > w.cylinder_radius)
        return false;
    } else if ((x - w.center).dot(s.n_in) < 0) {
      return false;
    }
  }
  return true;
}

// The vessel of the card's specimen shape, every length multiplied by `scale`.
Vessel make_vessel(Model& m, const MaterialCard& card, double scale) {
  Vessel v;
  v.dim = card.dim;
  v.shape = card.vessel.shape;
  const Vec3 L = card.vessel.size * scale;
  const double big = 1.5 * L.maxCoeff();
  auto add_plane = [&](const std::string& name, const Vec3& p, const Vec3& n) {
    m.walls.push_back(plane_wall(card.dim, name, p, n, big));
    v.servos.push_back({m.walls.size() - 1, n, false});
  };
  switch (card.vessel.shape) {
  case SpecimenShape::Rectangle:
  case SpecimenShape::Prism: {
    const char* names[3] = {"x", "y", "z"};
    for (int d = 0; d < card.dim; ++d)
      for (int side = 0; side < 2; ++side) {
        Vec3 p = Vec3::Zero(), n = Vec3::Zero();
        p[d] = side ? 0.5 * L[d] : -0.5 * L[d];
        n[d] = side ? -1 : 1;
        add_plane(std::string("vessel.") + names[d] + (side ? "max" : "min"), p, n);
      }
    break;
  }
  case SpecimenShape::Disk2D:
  case SpecimenShape::Cylinder:
  case SpecimenShape::Disk3D: {
    const double h = card.dim == 3 ? L.y() : 0;
    m.walls.push_back(round_wall(0.5 * L.x()));
    v.servos.push_back({m.walls.size() - 1, Vec3::Zero(), true});
    if (card.dim == 3) {
      add_plane("vessel.bottom", Vec3(0, 0, -0.5 * h), Vec3::UnitZ());
      add_plane("vessel.top", Vec3(0, 0, 0.5 * h), -Vec3::UnitZ());
    }
    break;
  }
  }
  return v;
}

void Run::servo_step(double target) {
  wall_stiffness_sums(m, k_sums);
  const double dt = std::max(m.timestep(), 1e-12);
  for (const Servo& s : vessel.servos) {
    const double vmax = speed_cap * r_avg / dt * vessel.half_extent(m, s) / largest_half;
    const double v = servo_velocity(0.5, vessel.area(m, s), k_sums[s.wall], dt,
                                    target - vessel.stress(m, s), vmax);
    Wall& w = m.walls[s.wall];
    if (s.radial)
      w.radial_velocity = -v;
    else
      w.velocity = v * s.n_in;
  }
}

bool Run::stresses_within(double target, double tol) const {
  for (const Servo& s : vessel.servos)
    if (std::abs(vessel.stress(m, s) - target) > tol * target)
      return false;
  return true;
}

double Run::porosity_now() const {
  return 1 - grain_volume_sum(m) / vessel.volume(m);
}

} // namespace rocklab::genesis
