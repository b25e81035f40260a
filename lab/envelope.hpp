// The rock's strength envelope from the peaks of compression tests at several confinements:
// Mohr-Coulomb (friction angle, cohesion) and Hoek-Brown for intact rock (m_i, sigma_c). Used by
// the triaxial test's part of a suite's properties. Units SI, stresses compression positive.
#pragma once

#include <vector>

namespace rocklab {

/// Strength envelopes from (confinement, peak axial stress) pairs, SI.
struct Envelope {
  int points = 0;
  double friction_angle_deg = 0, cohesion = 0, r2_mc = 0; ///< Mohr-Coulomb, >= 2 confinements
  bool has_mc = false;
  double hb_mi = 0, hb_sigma_c = 0, r2_hb = 0; ///< Hoek-Brown (intact, s = 1), >= 3 confinements
  /// Root-mean-square of (fitted sigma1 - measured sigma1) / measured sigma1 over the points
  double hb_fit_error = 0;
  bool has_hb = false;
  double sigma3_max = 0; ///< the highest confinement fitted [Pa]
};
Envelope fit_envelope(const std::vector<double>& sigma3, const std::vector<double>& sigma1);

} // namespace rocklab
