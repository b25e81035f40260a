#include "lab/frame/elastic_fit.hpp"

namespace rocklab {

namespace {

// Least squares of load and lateral strain against axial strain over the samples in [begin, end)
// with lo <= load <= hi.
template <class It> ElasticFit least_squares(It begin, It end, double lo, double hi) {
  ElasticFit f;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0, sl = 0, sxl = 0;
  for (It it = begin; it != end; ++it) {
    const LabSample& p = *it;
    if (p.load < lo || p.load > hi)
      continue;
    n += 1;
    sx += p.axial_strain;
    sy += p.load;
    sxx += p.axial_strain * p.axial_strain;
    sxy += p.axial_strain * p.load;
    syy += p.load * p.load;
    sl += p.lateral_strain;
    sxl += p.axial_strain * p.lateral_strain;
  }
  f.points = static_cast<std::size_t>(n);
  const double den = n * sxx - sx * sx;
  if (n >= 2 && den > 0) {
    f.youngs_modulus = (n * sxy - sx * sy) / den;
    f.poisson_ratio = -(n * sxl - sx * sl) / den;
    const double vy = n * syy - sy * sy;
    f.r2 = vy > 0 ? (n * sxy - sx * sy) * (n * sxy - sx * sy) / (den * vy) : 0.0;
  }
  return f;
}

} // namespace

ElasticFit fit_window(const std::vector<LabSample>& s, double lo, double hi) {
  return least_squares(s.begin(), s.end(), lo, hi);
}

ElasticFit fit_elastic(const std::vector<LabSample>& s, double peak, double lo, double hi) {
  auto end = s.begin();
  while (end != s.end() && !(peak > 0 && end->load >= peak))
    ++end;
  return least_squares(s.begin(), end, lo * peak, hi * peak);
}

} // namespace rocklab
