// The frame's gauges: platen (grip) force and separation, the confining walls' stresses and
// widths, the lateral strain (from the walls, or from the lateral-surface grains when unconfined).
// The protocol turns them into the test's strain and stresses.
#include "lab/frame/loading_frame.hpp"

#include "lab/protocols/frame_protocol.hpp"

#include <cassert>
#include <cmath>
#include <numbers>

namespace rocklab {

namespace {
constexpr double kPi = std::numbers::pi;
}

double LoadingFrame::separation() const {
  assert((top_ >= 0 || !grip_top_.empty()) && "the frame has platens or grips");
  const int axis = geo_.axis;
  if (top_ >= 0)
    return m_.walls[static_cast<std::size_t>(top_)].center[axis] -
           m_.walls[static_cast<std::size_t>(bottom_)].center[axis];
  double zt = 0, zb = 0;
  for (std::int32_t i : grip_top_)
    zt += m_.balls.pos[static_cast<std::size_t>(i)][axis];
  for (std::int32_t i : grip_bottom_)
    zb += m_.balls.pos[static_cast<std::size_t>(i)][axis];
  return zt / static_cast<double>(grip_top_.size()) - zb / static_cast<double>(grip_bottom_.size());
}

double LoadingFrame::lateral_width(int d) const {
  double w = 0;
  for (std::size_t j = 0; j < lateral_.size(); ++j)
    if (lateral_axis_[j] == d)
      w += lateral_sign_[j] * m_.walls[static_cast<std::size_t>(lateral_[j])].center[d];
  return w;
}

double LoadingFrame::face_area(std::size_t k) const {
  const double h = top_ >= 0 ? separation() : geo_.height0;
  if (lateral_axis_[k] < 0)
    return 2 * kPi * m_.walls[static_cast<std::size_t>(lateral_[k])].cylinder_radius * h;
  if (geo_.dim == 2)
    return h; // unit thickness
  const int other = 3 - geo_.axis - lateral_axis_[k];
  return h * lateral_width(other);
}

double LoadingFrame::lateral_stress_of(std::size_t k) const {
  const Wall& w = m_.walls[static_cast<std::size_t>(lateral_[k])];
  const double f =
      lateral_axis_[k] < 0 ? w.radial_force : lateral_sign_[k] * w.force[lateral_axis_[k]];
  return f / face_area(k);
}

double LoadingFrame::current_area(double lateral_strain) const {
  if (!lateral_.empty()) {
    if (lateral_axis_[0] < 0) {
      const double r = m_.walls[static_cast<std::size_t>(lateral_[0])].cylinder_radius;
      return kPi * r * r;
    }
    double a = 1;
    for (int d = 0; d < geo_.dim; ++d)
      if (d != geo_.axis)
        a *= lateral_width(d);
    return a;
  }
  // Unconfined: the initial section widened by the measured lateral strain.
  const double f = 1 - lateral_strain;
  return geo_.dim == 2 ? geo_.area0 * f : geo_.area0 * f * f;
}

double LoadingFrame::current_volume() const {
  if (geo_.diametral)
    return geo_.volume;
  return current_area(current().lateral_strain) * separation();
}

double LoadingFrame::lateral_strain() const {
  // Compression positive (bulging is negative).
  if (lateral_.empty())
    return !shell_.empty() && shell_ref_.size() == shell_.size() ? shell_strain() : 0.0;
  if (lateral_axis_[0] < 0) {
    const double r = m_.walls[static_cast<std::size_t>(lateral_[0])].cylinder_radius;
    return -(r - lateral_ref_[0]) / lateral_ref_[0];
  }
  double sum = 0;
  int k = 0;
  for (int d = 0; d < geo_.dim; ++d)
    if (d != geo_.axis) {
      sum += -(lateral_width(d) - lateral_ref_[d]) / lateral_ref_[d];
      ++k;
    }
  return sum / k;
}

double LoadingFrame::shell_strain() const {
  // The mean outward displacement of the lateral-surface grains: radial for a cylinder, the two
  // opposite faces' difference on each axis across the loading axis for a prism.
  const SpecimenGeometry& g = geo_;
  if (g.round) {
    double ur = 0;
    for (std::size_t k = 0; k < shell_.size(); ++k) {
      const Vec3 x0 = shell_ref_[k] - g.center;
      const Vec3 er = Vec3(x0.x(), x0.y(), 0).normalized();
      ur += (m_.balls.pos[static_cast<std::size_t>(shell_[k])] - shell_ref_[k]).dot(er);
    }
    return -ur / static_cast<double>(shell_.size()) / (0.5 * g.width0.x());
  }
  double sum = 0;
  int k = 0;
  for (int d = 0; d < g.dim; ++d) {
    if (d == g.axis)
      continue;
    double up = 0, un = 0;
    int np = 0, nn = 0;
    for (std::size_t j = 0; j < shell_.size(); ++j) {
      const double x0 = shell_ref_[j][d] - g.center[d];
      if (std::abs(x0) < 0.25 * g.width0[d])
        continue; // a grain on one of the other faces
      const double u = m_.balls.pos[static_cast<std::size_t>(shell_[j])][d] - shell_ref_[j][d];
      (x0 > 0 ? up : un) += u;
      (x0 > 0 ? np : nn) += 1;
    }
    if (np > 0 && nn > 0) {
      sum += -(up / np - un / nn) / g.width0[d];
      ++k;
    }
  }
  return k ? sum / k : 0.0;
}

void LoadingFrame::measure(LabSample& s) const {
  s.step = m_.step();
  s.time = m_.time();
  // Platen (grip) force; > 0 compresses the specimen (in direct tension: > 0 pulls it).
  const int axis = geo_.axis;
  if (top_ >= 0) {
    s.force = 0.5 * (m_.walls[static_cast<std::size_t>(top_)].force[axis] -
                     m_.walls[static_cast<std::size_t>(bottom_)].force[axis]);
  } else {
    double ft = 0, fb = 0;
    for (std::int32_t i : grip_top_)
      ft -= m_.balls.force[static_cast<std::size_t>(i)][axis];
    for (std::int32_t i : grip_bottom_)
      fb += m_.balls.force[static_cast<std::size_t>(i)][axis];
    s.force = 0.5 * (ft + fb);
  }
  const bool loading = phase_ >= kLoad;
  s.axial_strain = loading ? test_.axial_strain(*this) : 0.0;
  s.lateral_strain = loading && !geo_.diametral ? lateral_strain() : 0.0;
  s.lateral_stress = 0;
  for (std::size_t k = 0; k < lateral_.size(); ++k)
    s.lateral_stress += lateral_stress_of(k) / static_cast<double>(lateral_.size());
  test_.stresses(*this, s);
}

} // namespace rocklab
