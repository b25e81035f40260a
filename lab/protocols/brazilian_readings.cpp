// The Brazilian test's readings while loading (lab/protocols/brazilian.hpp): the split's crack run,
// the tension the disk carries across its loaded diameter, when it lost it, the strongest reading
// before that, and the arc over which the platens load the disk. A flat platen on a round disk
// touches one or two rim grains; a cushion, a sunk platen or flats spread the load over more of the
// rim, and the centre's tension under a load spread uniformly over two arcs 2a is 2F/(pi D t) x
// (sin 2a - a) / a (Hondros 1959), below the line-load value. Units SI.
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

SplitBins::SplitBins(const SpecimenGeometry& g, double fraction)
    : d_(g.width0.y()), centre_(g.center),
      need_(static_cast<int>(std::ceil(fraction * 10.0 - 1e-9))) {}

bool SplitBins::add(const Crack& c) {
  const Vec3 rel = c.position - centre_;
  if (std::abs(rel.x()) <= 0.2 * d_) {
    const double t = (rel.y() + 0.5 * d_) / d_;
    bins_[static_cast<std::size_t>(std::clamp(static_cast<int>(std::floor(t * 10.0)), 0, 9))] =
        true;
  }
  int longest = 0;
  auto cracked = [&](int i) { return i < 10 && bins_[static_cast<std::size_t>(i)]; };
  for (int a = 0; a < 10; ++a) { // the run from each cracked tenth, with at most one bridge
    if (!cracked(a))
      continue;
    int b = a;
    bool bridged = false;
    for (;;) {
      if (cracked(b + 1)) {
        b += 1;
      } else if (!bridged && cracked(b + 2)) {
        b += 2;
        bridged = true;
      } else {
        break;
      }
    }
    longest = std::max(longest, b - a + 1);
  }
  return longest >= need_;
}

double flat_disk_factor(double loading_angle) {
  const double a = 0.5 * loading_angle;
  return a > 0 ? (std::sin(2 * a) - a) / a : 1.0;
}

std::int64_t split_crack_step(const std::vector<Crack>& cracks, const SpecimenGeometry& g,
                              double fraction) {
  SplitBins bins(g, fraction);
  for (const Crack& c : cracks)
    if (bins.add(c))
      return c.step;
  return -1;
}

LabSample strongest_before(const std::vector<LabSample>& samples, const PeakRecord& peak,
                           std::int64_t split) {
  LabSample best;
  best.load = -1;
  if (split < 0)
    return best;
  if (peak.step >= 0 && peak.step <= split) {
    best.step = peak.step, best.time = peak.time, best.axial_strain = peak.strain;
    best.axial_stress = peak.stress, best.load = peak.load, best.force = peak.force;
    return best;
  }
  for (const LabSample& s : samples)
    if (s.step <= split && s.load > best.load)
      best = s;
  return best;
}

} // namespace rocklab
