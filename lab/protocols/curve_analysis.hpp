// What a compression curve says about the rock: the elastic constants over the linear part of the
// loading branch (chosen from the curve, before crack onset), the ISRM tangent at 50 % of the peak
// beside them, the crack-initiation and crack-damage stresses, and the checks that keep
// physically impossible numbers out of results. Units SI; stresses and strains compression
// positive.
#pragma once

#include "lab/crack_monitor.hpp"
#include "lab/frame/loading_frame.hpp"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace rocklab {

/// The loading branch up to the peak and what the frame knows about it.
struct CurveInput {
  int dim = 3;
  std::vector<LabSample> samples;   ///< loading samples, in order, up to and including the peak
  std::vector<std::int64_t> cracks; ///< cumulative crack count at each sample
  double load_ref = 0;              ///< the load when loading began (seating stress) [Pa]
  double peak = 0;                  ///< peak load [Pa]
};

/// A point of the curve where something starts: its load (deviator) and axial strain.
struct CurvePoint {
  double load = 0, axial_strain = 0;
};

struct CurveAnalysis {
  // Elastic constants over the linear window.
  double youngs_modulus = 0, poisson_ratio = 0, r2 = 0;
  double window_lo = 0, window_hi = 0; ///< loads bounding the window [Pa]
  std::size_t points = 0;
  bool before_cracking = false; ///< the window ends at or before the crack onset
  // ISRM suggested method: tangent over 40-60 % of the peak; secant to 50 % of the peak.
  double tangent50 = 0, poisson50 = 0, secant50 = 0;
  // Crack stresses (deviator, absolute) where found.
  std::optional<CurvePoint> ci_count, ci_volumetric, cd;
  std::vector<double> crack_volumetric_strain; ///< per sample, Martin & Chandler (1994)
  std::vector<std::string> warnings;
};

/// Fraction of the peak load at which the window starts (past seating and the platen ramp), at
/// which it ends at the latest, and the crack count (fraction of the count at the peak) that
/// marks crack initiation; the crack volumetric strain (fraction of the elastic axial strain at the
/// peak) beyond which the volume has left its elastic line.
inline constexpr double kWindowStart = 0.05, kWindowEnd = 0.5, kOnsetCrackFraction = 0.01;
inline constexpr double kVolumetricTolerance = 0.005;

CurveAnalysis analyse_curve(const CurveInput& in);

/// The analysis as results.json keys (youngs_modulus_Pa, poisson_ratio, elastic_fit,
/// crack_initiation_stress_Pa, crack_damage_stress_Pa, ..., warnings).
void write_curve_results(const CurveAnalysis& a, double peak, nlohmann::json& r);

} // namespace rocklab
