// Where a Brazilian disk's fracture started, and whether the test is valid in ISRM's sense (the
// splitting fracture starts in the centre region of the loaded diameter, not at a loading point;
// ISRM 1978, Suggested methods for determining tensile strength of rock materials). Units SI.
#include "lab/protocols/brazilian.hpp"

#include <algorithm>
#include <cmath>

namespace rocklab {

SplitOrigin split_origin(const std::vector<Crack>& cracks, const SpecimenGeometry& g,
                         std::int64_t until) {
  SplitOrigin o;
  const double d = g.width0.y();
  std::vector<double> along; // |y| / (D/2) of the diametral band's cracks, in the order they formed
  for (const Crack& c : cracks) {
    if (c.step > until)
      break;
    const Vec3 rel = c.position - g.center;
    if (std::abs(rel.x()) <= 0.2 * d)
      along.push_back(std::min(1.0, std::abs(rel.y()) / (0.5 * d)));
  }
  o.cracks = static_cast<int>(along.size());
  if (along.empty()) {
    o.site = "none";
    return o;
  }
  // The damage at the strength: the share within D/6 of a platen (the outer thirds of the
  // diameter; a uniform scatter along it puts a third there).
  o.platen_share = static_cast<double>(std::count_if(along.begin(), along.end(),
                                                     [](double a) { return a > 2.0 / 3.0; })) /
                   static_cast<double>(along.size());
  // Where it started: the median position of its first quarter of cracks (at least 3).
  const std::size_t n = std::min(along.size(), std::max<std::size_t>(3, (along.size() + 3) / 4));
  std::vector<double> first(along.begin(), along.begin() + static_cast<std::ptrdiff_t>(n));
  std::nth_element(first.begin(), first.begin() + static_cast<std::ptrdiff_t>(n / 2), first.end());
  o.start = first[n / 2];
  const bool at_platen = o.start > 2.0 / 3.0 || o.platen_share > kPlatenShareInvalid;
  o.site = at_platen ? "platen" : o.start <= 1.0 / 3.0 ? "centre" : "diameter";
  o.valid = !at_platen;
  return o;
}

} // namespace rocklab
