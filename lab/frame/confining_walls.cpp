// The confining walls of a triaxial (2D: biaxial) test: mounting, their stresses, section and
// lateral strain, and the stress servo (lab/frame/fixtures.hpp).
#include "lab/frame/fixtures.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab {

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kServoIntegralSteps = 100; ///< integral time of the confining servo [steps]
} // namespace

void ConfiningWalls::mount(Model& m, const SpecimenGeometry& g, const LinearProps& contact) {
  // A cylinder around a round specimen, plates on the faces of a prism (2D: on the sides),
  // frictionless: a lubricated membrane.
  LinearProps props = contact;
  props.fric = 0;
  const Vec3 e = unit_axis(g.axis);
  if (g.round) {
    Wall w;
    w.name = "confinement";
    w.cylinder_radius = 0.5 * g.width0.x();
    w.center = g.center;
    w.axis = e;
    w.update_bounds();
    walls_.push_back(add_machine_wall(m, std::move(w), props));
    axis_.push_back(-1);
    sign_.push_back(1);
  } else {
    const double span = g.machine_span();
    for (int d = 0; d < g.dim; ++d) {
      if (d == g.axis)
        continue;
      for (int side = 0; side < 2; ++side) {
        Vec3 pt = g.center;
        pt[d] = side ? g.hi[d] : g.lo[d];
        const Vec3 nrm = side ? Vec3(-unit_axis(d)) : unit_axis(d);
        const std::string name = std::string("confinement.") + "xyz"[d] + (side ? "max" : "min");
        walls_.push_back(add_machine_wall(m, machine_wall(g.dim, name, pt, nrm, span), props));
        axis_.push_back(d);
        sign_.push_back(side ? 1.0 : -1.0);
      }
    }
  }
  integral_.assign(walls_.size(), 0.0);
}

double ConfiningWalls::width(const Model& m, int d) const {
  double w = 0;
  for (std::size_t j = 0; j < walls_.size(); ++j)
    if (axis_[j] == d)
      w += sign_[j] * m.walls[static_cast<std::size_t>(walls_[j])].center[d];
  return w;
}

double ConfiningWalls::face_area(const Model& m, const SpecimenGeometry& g, double h,
                                 std::size_t k) const {
  if (axis_[k] < 0)
    return 2 * kPi * m.walls[static_cast<std::size_t>(walls_[k])].cylinder_radius * h;
  if (g.dim == 2)
    return h; // unit thickness
  const int other = 3 - g.axis - axis_[k];
  return h * width(m, other);
}

double ConfiningWalls::stress(const Model& m, const SpecimenGeometry& g, double h,
                              std::size_t k) const {
  const Wall& w = m.walls[static_cast<std::size_t>(walls_[k])];
  const double f = axis_[k] < 0 ? w.radial_force : sign_[k] * w.force[axis_[k]];
  return f / face_area(m, g, h, k);
}

double ConfiningWalls::mean_stress(const Model& m, const SpecimenGeometry& g, double h) const {
  double s = 0;
  for (std::size_t k = 0; k < walls_.size(); ++k)
    s += stress(m, g, h, k) / static_cast<double>(walls_.size());
  return s;
}

bool ConfiningWalls::within(const Model& m, const SpecimenGeometry& g, double h, double target,
                            double tol) const {
  for (std::size_t k = 0; k < walls_.size(); ++k)
    if (!(std::abs(stress(m, g, h, k) - target) <= tol * target))
      return false;
  return true;
}

double ConfiningWalls::area(const Model& m, const SpecimenGeometry& g) const {
  if (axis_[0] < 0) {
    const double r = m.walls[static_cast<std::size_t>(walls_[0])].cylinder_radius;
    return kPi * r * r;
  }
  double a = 1;
  for (int d = 0; d < g.dim; ++d)
    if (d != g.axis)
      a *= width(m, d);
  return a;
}

void ConfiningWalls::mark_reference(const Model& m, const SpecimenGeometry& g) {
  ref_.setZero();
  if (walls_.empty())
    return;
  if (axis_[0] < 0)
    ref_[0] = m.walls[static_cast<std::size_t>(walls_[0])].cylinder_radius;
  else
    for (int d = 0; d < g.dim; ++d)
      if (d != g.axis)
        ref_[d] = width(m, d);
}

double ConfiningWalls::strain(const Model& m, const SpecimenGeometry& g) const {
  // Compression positive (bulging is negative).
  if (axis_[0] < 0) {
    const double r = m.walls[static_cast<std::size_t>(walls_[0])].cylinder_radius;
    return -(r - ref_[0]) / ref_[0];
  }
  double sum = 0;
  int k = 0;
  for (int d = 0; d < g.dim; ++d)
    if (d != g.axis) {
      sum += -(width(m, d) - ref_[d]) / ref_[d];
      ++k;
    }
  return sum / k;
}

void ConfiningWalls::gather_follow_sums(const Model& m) {
  // Per wall: the force-weighted inward velocity of the grains touching it (feed-forward).
  // Buffers are reused: nothing is allocated per step.
  const std::size_t nw = m.walls.size();
  wall_f_.assign(nw, 0.0);
  wall_fv_.assign(nw, 0.0);
  of_wall_.assign(nw, -1);
  for (std::size_t k = 0; k < walls_.size(); ++k)
    of_wall_[static_cast<std::size_t>(walls_[k])] = static_cast<int>(k);
  const auto& cs = m.contacts();
  const auto& os = m.contact_outputs();
  for (std::size_t ci = 0; ci < cs.size(); ++ci) {
    if (cs[ci].kind != ContactKind::BallFacet)
      continue;
    const auto wall = static_cast<std::size_t>(cs[ci].end2);
    const int k = of_wall_[wall];
    if (k < 0)
      continue;
    const double f = os[ci].force.norm();
    if (f <= 0)
      continue;
    const Wall& w = m.walls[wall];
    const auto b = static_cast<std::size_t>(cs[ci].end1);
    const Vec3& vel = m.balls.vel[b];
    const auto kk = static_cast<std::size_t>(k);
    double inward;
    if (axis_[kk] < 0) {
      Vec3 r = m.balls.pos[b] - w.center;
      r -= r.dot(w.axis) * w.axis;
      const double rn = r.norm();
      inward = rn > 0 ? -vel.dot(r) / rn : 0.0;
    } else {
      inward = -sign_[kk] * vel[axis_[kk]];
    }
    wall_f_[wall] += f;
    wall_fv_[wall] += f * inward;
  }
}

void ConfiningWalls::control(Model& m, const SpecimenGeometry& g, double h,
                             const std::vector<double>& wall_k) {
  const double target = target_;
  // Each wall follows the grains that touch it (feed-forward: the force-weighted mean of their
  // velocity along the wall normal, so a dilating specimen is followed without a standing
  // error), plus a proportional term that closes the whole stress error in one step and a small
  // integral trim (time constant 100 steps, limited to 5 % of the confinement) against any
  // remaining bias.
  gather_follow_sums(m);
  for (std::size_t k = 0; k < walls_.size(); ++k) {
    const auto wall = static_cast<std::size_t>(walls_[k]);
    const double s = stress(m, g, h, k);
    const double cap = 0.05 * target * kServoIntegralSteps;
    integral_[k] = std::clamp(integral_[k] + target - s, -cap, cap);
    const double follow = wall_f_[wall] > 0 ? wall_fv_[wall] / wall_f_[wall] : 0.0;
    const double v =
        machine_servo_velocity(m, g, wall_k[wall], target + integral_[k] / kServoIntegralSteps,
                               face_area(m, g, h, k), s) +
        follow;
    Wall& w = m.walls[wall];
    if (axis_[k] < 0)
      w.radial_velocity = -v;
    else
      w.velocity = -sign_[k] * v * unit_axis(axis_[k]);
  }
}

void ConfiningWalls::check(const Model& m, const std::string& file) const {
  const auto walls = static_cast<std::int64_t>(m.walls.size());
  bool ok = axis_.size() == walls_.size() && sign_.size() == walls_.size() &&
            integral_.size() == walls_.size();
  for (std::int64_t w : walls_)
    ok = ok && w >= 0 && w < walls;
  if (!ok)
    throw InputError(file + ": corrupt checkpoint (confining wall out of range)");
}

} // namespace rocklab
