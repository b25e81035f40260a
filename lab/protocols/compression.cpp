#include "lab/protocols/compression.hpp"

#include "lab/frame/elastic_fit.hpp"

namespace rocklab {

double CompressionTest::axial_strain(const LoadingFrame& f) const {
  return (f.sep_ref() - f.separation()) / f.sep_ref(); // platen shortening over the height
}

void CompressionTest::stresses(const LoadingFrame& f, LabSample& s) const {
  s.axial_stress = s.force / f.current_area(s.lateral_strain);
  s.load = s.axial_stress - s.lateral_stress; // the deviator (UCS: the axial stress)
}

namespace {

// Loading and unloading slopes over the same strain range (20-100 % of the reversal), each once
// the platens run at full speed (after the ramps at the start and the turn).
void unloading_moduli(const LoadingFrame& f, nlohmann::json& r) {
  const Protocol& p = f.protocol();
  std::vector<LabSample> up, down;
  for (const LabSample& s : f.samples()) {
    if (s.axial_strain < 0.2 * p.reverse_at_strain)
      continue;
    if (s.step <= f.reverse_step()) {
      if (s.step >= f.load_start_step() + p.ramp_steps)
        up.push_back(s);
    } else if (s.step >= f.reverse_step() + p.ramp_steps) {
      down.push_back(s);
    }
  }
  r["youngs_modulus_loading_Pa"] = fit_elastic(up, 1e300, -1e300, 1e300).youngs_modulus;
  r["youngs_modulus_unloading_Pa"] = fit_elastic(down, 1e300, -1e300, 1e300).youngs_modulus;
}

} // namespace

void CompressionTest::results(const LoadingFrame& f, nlohmann::json& r) const {
  const PeakRecord& peak = f.peak();
  const std::vector<LabSample>& samples = f.samples();
  // Tangent modulus and Poisson's ratio at 40-60 % of the peak, secant at 50 %, initial over
  // the first 1 % of the peak load.
  const ElasticFit tangent = fit_elastic(samples, peak.load, 0.4, 0.6);
  double secant = 0;
  for (const LabSample& s : samples)
    if (s.load >= 0.5 * peak.load && s.axial_strain > 0) {
      secant = (s.load - f.load_ref()) / s.axial_strain;
      break;
    }
  std::vector<LabSample> early;
  for (const LabSample& s : samples)
    if (s.load - f.load_ref() <= 0.01 * peak.load && s.step <= peak.step)
      early.push_back(s);
  const ElasticFit initial = fit_elastic(early, 1e300, -1e300, 1e300);
  r["youngs_modulus_Pa"] = tangent.youngs_modulus;
  r["youngs_modulus_secant_Pa"] = secant;
  r["youngs_modulus_initial_Pa"] = initial.youngs_modulus;
  r["poisson_ratio"] = tangent.poisson_ratio;
  r["peak_stress_Pa"] = peak.stress;
  r["peak_deviator_Pa"] = peak.load;
  r["peak_axial_strain"] = peak.strain;
  r["peak_lateral_strain"] = peak.lateral;
  r["confinement_Pa"] = f.protocol().confinement;
  if (f.confined())
    r["confinement_measured_Pa"] = f.confinement_band().json(f.protocol().confinement);
  if (f.protocol().reverse_at_strain > 0)
    unloading_moduli(f, r);
}

PlotLabels CompressionTest::plot_labels() const {
  return {"strain [%] (compression positive)", "axial stress [MPa]", true, 1};
}

} // namespace rocklab
