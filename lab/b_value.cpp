#include "lab/b_value.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace rocklab {

BValue b_value(const std::vector<double>& magnitudes) {
  BValue out;
  out.b = out.standard_error = out.completeness = std::numeric_limits<double>::quiet_NaN();
  std::map<long, int> bins; // bin index -> count (ordered: ties go to the lower bin)
  for (const double m : magnitudes)
    if (std::isfinite(m))
      ++bins[static_cast<long>(std::floor(m / kMagnitudeBin))];
  if (bins.empty())
    return out;
  const auto top = std::max_element(
      bins.begin(), bins.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  const double mc = static_cast<double>(top->first) * kMagnitudeBin;
  out.completeness = mc;
  double sum = 0;
  int n = 0;
  for (const double m : magnitudes)
    if (std::isfinite(m) && m >= mc)
      sum += m, ++n;
  out.events = n;
  if (n < kMinBValueEvents)
    return out;
  const double mean = sum / n;
  double ss = 0;
  for (const double m : magnitudes)
    if (std::isfinite(m) && m >= mc)
      ss += (m - mean) * (m - mean);
  if (!(mean > mc))
    return out;
  out.b = std::log10(std::exp(1.0)) / (mean - mc);
  out.standard_error = 2.30 * out.b * out.b * std::sqrt(ss / (static_cast<double>(n) * (n - 1)));
  return out;
}

} // namespace rocklab
