// The frame's gauges: the load and separation of the platens (grips), the confining walls'
// stress, the lateral strain (from the walls, or from the lateral-surface grains when unconfined).
// The protocol turns them into the test's strain and stresses.
#include "lab/frame/loading_frame.hpp"

#include "lab/frame/frame_test.hpp"

#include <cmath>

namespace rocklab {

double LoadingFrame::separation() const {
  return actuator_->separation(m_, geo_.axis);
}

double LoadingFrame::wall_height() const {
  return actuator_->wall() >= 0 ? separation() : geo_.height0;
}

double LoadingFrame::current_area(double lateral_strain) const {
  if (confinement_)
    return confinement_->area(m_, geo_);
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
  if (!confinement_)
    return !shell_.empty() && shell_ref_.size() == shell_.size() ? shell_strain() : 0.0;
  return confinement_->strain(m_, geo_);
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
  s.force = actuator_->force(m_, geo_.axis);
  const bool loading = phase_ >= kLoad;
  s.axial_strain = loading ? test_.axial_strain(*this) : 0.0;
  s.lateral_strain = loading && !geo_.diametral ? lateral_strain() : 0.0;
  s.lateral_stress = confinement_ ? confinement_->mean_stress(m_, geo_, wall_height()) : 0.0;
  test_.stresses(*this, s);
}

} // namespace rocklab
