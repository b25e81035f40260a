#include "lab/frame/elastic_fit.hpp"

namespace rocklab {

ElasticFit fit_elastic(const std::vector<LabSample>& s, double peak, double lo, double hi) {
  // Least squares over the pre-peak samples with lo*peak <= load <= hi*peak.
  ElasticFit f;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, sl = 0, sxl = 0;
  for (const LabSample& p : s) {
    if (p.load >= peak && peak > 0)
      break;
    if (p.load < lo * peak || p.load > hi * peak)
      continue;
    n += 1;
    sx += p.axial_strain;
    sy += p.load;
    sxx += p.axial_strain * p.axial_strain;
    sxy += p.axial_strain * p.load;
    sl += p.lateral_strain;
    sxl += p.axial_strain * p.lateral_strain;
  }
  f.points = static_cast<std::size_t>(n);
  const double den = n * sxx - sx * sx;
  if (n >= 2 && den > 0) {
    f.youngs_modulus = (n * sxy - sx * sy) / den;
    f.poisson_ratio = -(n * sxl - sx * sl) / den;
  }
  return f;
}

} // namespace rocklab
