#include "lab/envelope.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

namespace rocklab {

namespace {

// Least-squares line y = a + b x; returns {a, b, r2}.
std::array<double, 3> line_fit(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0, sy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
  }
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  const double b = sxy / sxx;
  const double r2 = syy > 0 ? sxy * sxy / (sxx * syy) : 1.0;
  return {my - b * mx, b, r2};
}

} // namespace

Envelope fit_envelope(const std::vector<double>& s3, const std::vector<double>& s1) {
  Envelope e;
  e.points = static_cast<int>(s3.size());
  for (double x : s3)
    e.sigma3_max = std::max(e.sigma3_max, x);
  std::set<double> distinct(s3.begin(), s3.end());
  if (distinct.size() >= 2) {
    // Mohr-Coulomb: sigma1 = sigma_c + q sigma3, q = (1 + sin phi) / (1 - sin phi),
    // c = sigma_c / (2 sqrt(q)).
    const auto [a, q, r2] = line_fit(s3, s1);
    if (q > 1 && a > 0) {
      e.has_mc = true;
      e.friction_angle_deg = std::asin((q - 1) / (q + 1)) * 180.0 / 3.14159265358979323846;
      e.cohesion = a / (2 * std::sqrt(q));
      e.r2_mc = r2;
    }
  }
  if (distinct.size() >= 3) {
    // Hoek-Brown for intact rock (s = 1): (sigma1 - sigma3)^2 = sigma_c^2 + m_i sigma_c sigma3,
    // a straight line in sigma3 whose intercept gives sigma_c and slope m_i sigma_c.
    std::vector<double> y;
    for (std::size_t i = 0; i < s3.size(); ++i)
      y.push_back((s1[i] - s3[i]) * (s1[i] - s3[i]));
    const auto [a, b, r2] = line_fit(s3, y);
    if (a > 0 && b > 0) {
      e.has_hb = true;
      e.hb_sigma_c = std::sqrt(a);
      e.hb_mi = b / e.hb_sigma_c;
      e.r2_hb = r2;
      double q = 0; // sigma1 = sigma3 + sigma_c sqrt(m_i sigma3 / sigma_c + 1)
      for (std::size_t i = 0; i < s3.size(); ++i) {
        const double fit = s3[i] + e.hb_sigma_c * std::sqrt(e.hb_mi * s3[i] / e.hb_sigma_c + 1);
        q += (fit / s1[i] - 1) * (fit / s1[i] - 1);
      }
      e.hb_fit_error = std::sqrt(q / static_cast<double>(s3.size()));
    }
  }
  return e;
}

} // namespace rocklab
