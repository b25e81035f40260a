// Where a Brazilian disk's fracture started, and whether the test is valid in ISRM's sense (the
// splitting fracture starts in the centre region of the loaded diameter, not at a loading point;
// ISRM 1978, Suggested methods for determining tensile strength of rock materials). Units SI.
#include "lab/protocols/brazilian.hpp"

#include <algorithm>
#include <cmath>

namespace rocklab {

double binomial_upper_tail(int k, int n, double p) {
  if (k <= 0)
    return 1;
  if (k > n)
    return 0;
  double sum = 0; // the terms in logs: n reaches thousands of cracks
  const double lp = std::log(p), lq = std::log1p(-p), ln_n = std::lgamma(n + 1.0);
  for (int i = k; i <= n; ++i)
    sum += std::exp(ln_n - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) + i * lp + (n - i) * lq);
  return std::min(1.0, sum);
}

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
  auto at_platen = [](double a) { return a > 2.0 / 3.0; };
  const int near = static_cast<int>(std::count_if(along.begin(), along.end(), at_platen));
  o.platen_share = near / static_cast<double>(along.size());
  // Where it started: the median position of its first quarter of cracks (at least 3).
  const std::size_t n = std::min(along.size(), std::max<std::size_t>(3, (along.size() + 3) / 4));
  std::vector<double> first(along.begin(), along.begin() + static_cast<std::ptrdiff_t>(n));
  o.first = static_cast<int>(n);
  o.first_at_platen = static_cast<int>(std::count_if(first.begin(), first.end(), at_platen));
  std::nth_element(first.begin(), first.begin() + static_cast<std::ptrdiff_t>(n / 2), first.end());
  o.start = first[n / 2];
  // Either sign counts only beyond chance: with a tension nearly uniform along the loaded
  // diameter a third of its cracks fall within D/6 of a platen, so 4 of a first quarter of 7 do
  // so in 17 % of disks whose cracks are scattered evenly (2D: a few dozen diametral cracks).
  o.start_chance = binomial_upper_tail(o.first_at_platen, o.first, 1.0 / 3.0);
  o.share_chance = binomial_upper_tail(near, o.cracks, 1.0 / 3.0);
  const bool early = o.start > 2.0 / 3.0 && o.start_chance <= kPlatenChance;
  const bool crushed = o.platen_share > kPlatenShareInvalid && o.share_chance <= kPlatenChance;
  const bool platen = early || crushed;
  o.site = platen ? "platen" : o.start <= 1.0 / 3.0 ? "centre" : "diameter";
  o.valid = !platen;
  return o;
}

} // namespace rocklab
