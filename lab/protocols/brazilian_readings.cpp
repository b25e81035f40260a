// The Brazilian test's readings while loading (lab/protocols/brazilian.hpp): the tension the disk
// carries across its loaded diameter, when it lost it, and the arc over which the platens load the
// disk. A flat platen on a round disk touches one or two rim grains; a cushion, a sunk platen or
// flats spread the load over more of the rim, and the centre's tension under a load spread
// uniformly over two arcs 2a is 2F/(pi D t) x (sin 2a - a) / a (Hondros 1959), below the line-load
// value. Units SI.
#include "lab/protocols/brazilian.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace rocklab {

double ArcSums::half_width() const {
  if (w <= 0)
    return 0;
  const double mean = x / w;
  const double var = std::max(0.0, xx / w - mean * mean);
  return std::sqrt(3.0 * var); // uniform over [-a, a]: variance a^2 / 3
}

LoadedArc loaded_arc(const Model& m, const SpecimenGeometry& g) {
  std::array<ArcSums, 2> side{}; // [0] below the centre, [1] above
  const std::vector<Contact>& cs = m.contacts();
  const std::vector<ContactOutput>& out = m.contact_outputs();
  for (std::size_t i = 0; i < cs.size(); ++i) {
    if (cs[i].kind != ContactKind::BallFacet)
      continue;
    const Vec3 rel = out[i].xc - g.center;
    const double f = std::abs(out[i].force.y()); // the platens press along y
    if (!(f > 0))
      continue;
    side[rel.y() > 0 ? 1 : 0].add(rel.x(), f);
  }
  const double radius = 0.5 * g.width0.x();
  LoadedArc a;
  int sides = 0;
  for (const ArcSums& s : side) {
    a.contacts += s.n;
    if (s.w <= 0)
      continue;
    a.half_angle += std::asin(std::min(1.0, s.half_width() / radius));
    ++sides;
  }
  if (sides > 0)
    a.half_angle /= sides;
  return a;
}

double diametral_tension(const Model& m, const SpecimenGeometry& g) {
  std::array<double, 5> planes{};
  for (std::size_t k = 0; k < planes.size(); ++k)
    planes[k] = g.center.x() + (static_cast<double>(k) - 2.0) * 0.05 * g.width0.x();
  const std::vector<Contact>& cs = m.contacts();
  const std::vector<ContactOutput>& out = m.contact_outputs();
  double t = 0;
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const Contact& c = cs[i];
    if (c.kind != ContactKind::BallBall)
      continue;
    const double x1 = m.balls.pos[static_cast<std::size_t>(c.end1)].x();
    const double x2 = m.balls.pos[static_cast<std::size_t>(c.end2)].x();
    for (double x : planes) {
      if ((x1 - x) * (x2 - x) >= 0)
        continue; // does not cross this plane
      // The force on grain 2 pulls it back across the plane: tension.
      const double pull = x2 > x ? -out[i].force.x() : out[i].force.x();
      t += std::max(pull, 0.0);
    }
  }
  return t / static_cast<double>(planes.size());
}

void TensionWatch::add(const TensionReading& x) {
  if (lost_.step >= 0)
    return;
  peak_ = std::max(peak_, x.load);
  if (x.load < floor_ || x.load < failed_ * peak_)
    return; // the seating load, or a collapse: neither confirms nor ends a run
  if (ref_ > 0 && x.ratio < kept_ * ref_) {
    if (low_.step < 0)
      low_ = {x.step, ref_, x.ratio};
    if (x.step - low_.step >= persist_)
      lost_ = low_;
    return;
  }
  low_.step = -1;
  if (x.load >= 0.9 * peak_)
    ref_ = std::max(ref_, x.ratio);
}

TensionLoss TensionWatch::result() const {
  if (lost_.step >= 0)
    return lost_;
  if (low_.step >= 0)
    return low_; // still below when the test ended
  return {-1, ref_, 0};
}

TensionLoss tension_loss(const std::vector<TensionReading>& r, double kept, double failed,
                         double floor, std::int64_t persist) {
  TensionWatch w(kept, failed, floor, persist);
  for (const TensionReading& x : r) {
    w.add(x);
    if (w.lost().step >= 0)
      break;
  }
  return w.result();
}

} // namespace rocklab
