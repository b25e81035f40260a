#include "lab/protocols/compression.hpp"

#include "io/json_input.hpp"
#include "io/results.hpp"
#include "lab/frame/elastic_fit.hpp"
#include "lab/protocols/curve_analysis.hpp"

#include <cstdio>

namespace rocklab {

void CompressionTest::read_options(JsonObject& loading, JsonObject&, const Protocol&) {
  reverse_at_strain_ = loading.number("reverse_at_strain", {0, 0.1, false, false}, 0.0);
}

FrameSetup CompressionTest::compression_setup() const {
  FrameSetup s;
  s.reverse_at_strain = reverse_at_strain_;
  return s;
}

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
  const double reverse = f.frame_setup().reverse_at_strain;
  std::vector<LabSample> up, down;
  for (const LabSample& s : f.samples()) {
    if (s.axial_strain < 0.2 * reverse)
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

CurveInput CompressionTest::curve(const LoadingFrame& f) {
  CurveInput in;
  in.dim = f.geometry().dim;
  in.load_ref = f.load_ref();
  in.peak = f.peak().load;
  const auto& cracks = f.cracks().cracks();
  std::size_t k = 0;
  for (const LabSample& s : f.samples()) {
    if (s.step > f.peak().step)
      break;
    while (k < cracks.size() && cracks[k].step <= s.step)
      ++k;
    in.samples.push_back(s);
    in.cracks.push_back(static_cast<std::int64_t>(k));
  }
  return in;
}

void CompressionTest::results(const LoadingFrame& f, nlohmann::json& r) const {
  const PeakRecord& peak = f.peak();
  const std::vector<LabSample>& samples = f.samples();
  // Elastic constants over the linear window, ISRM tangent and secant at 50 %, crack stresses
  // (lab/protocols/curve_analysis.hpp); the initial modulus over the first 1 % of the peak load.
  write_curve_results(analyse_curve(curve(f)), peak.load, r);
  std::vector<LabSample> early;
  for (const LabSample& s : samples)
    if (s.load - f.load_ref() <= 0.01 * peak.load && s.step <= peak.step)
      early.push_back(s);
  r["youngs_modulus_initial_Pa"] = fit_elastic(early, 1e300, -1e300, 1e300).youngs_modulus;
  r["peak_stress_Pa"] = peak.stress;
  r["peak_deviator_Pa"] = peak.load;
  r["peak_axial_strain"] = peak.strain;
  r["peak_lateral_strain"] = peak.lateral;
  r["confinement_Pa"] = f.confining_stress();
  if (f.confined())
    r["confinement_measured_Pa"] = f.confinement_band().json(f.confining_stress());
  if (f.frame_setup().reverse_at_strain > 0)
    unloading_moduli(f, r);
}

PlotLabels CompressionTest::plot_labels() const {
  return {"strain [%] (compression positive)", "axial stress [MPa]", true, 1};
}

void CompressionTest::print_results(const nlohmann::json& r) const {
  auto shown = [&](const char* key, const char* fmt, double scale) {
    if (!r.contains(key) || !r[key].is_number())
      return std::string("not measured");
    char b[48];
    std::snprintf(b, sizeof b, fmt, r[key].get<double>() * scale);
    return std::string(b);
  };
  std::printf("peak stress  %.4g MPa (deviator %.4g MPa) at axial strain %.4g %%\n",
              1e-6 * json_number(r, "peak_stress_Pa", 0.0),
              1e-6 * json_number(r, "peak_deviator_Pa", 0.0),
              100 * json_number(r, "peak_axial_strain", 0.0));
  std::printf("E            %s over the linear window, %s secant at 50 %% of peak   poisson %s\n",
              shown("youngs_modulus_Pa", "%.4g GPa", 1e-9).c_str(),
              shown("youngs_modulus_secant_Pa", "%.4g GPa", 1e-9).c_str(),
              shown("poisson_ratio", "%.3f", 1).c_str());
  // A crack stress no crack marked (no cracks before the peak, a volume still falling) is null in
  // results.json and "not measured" here, not 0 MPa.
  auto stress_and_ratio = [&](const char* key, const char* ratio_key) {
    const std::string s = shown(key, "%.4g MPa", 1e-6);
    const auto& c = r["crack_stresses"];
    if (!c.contains(ratio_key) || !c[ratio_key].is_number())
      return s;
    char b[32];
    std::snprintf(b, sizeof b, " (%.2f of peak)", c[ratio_key].get<double>());
    return s + b;
  };
  if (r.contains("crack_stresses"))
    std::printf("crack stress initiation %s, volumetric %s; damage %s\n",
                stress_and_ratio("crack_initiation_stress_Pa", "crack_initiation_ratio").c_str(),
                shown("crack_initiation_stress_volumetric_Pa", "%.4g MPa", 1e-6).c_str(),
                stress_and_ratio("crack_damage_stress_Pa", "crack_damage_ratio").c_str());
  if (json_number(r, "confinement_Pa", 0.0) > 0)
    std::printf("confinement  %.4g MPa (held between %.4g and %.4g MPa)\n",
                1e-6 * json_number(r, "confinement_Pa", 0.0),
                1e-6 * r["confinement_measured_Pa"]["min"].get<double>(),
                1e-6 * r["confinement_measured_Pa"]["max"].get<double>());
}

// Where results.json has them, the crack-initiation and crack-damage stresses on the axial curve:
// the axial stress of the first sample at their axial strain (the deviator's peer).
void CompressionTest::plot_markers(const std::vector<LabSample>& samples, const nlohmann::json& r,
                                   std::vector<PlotMarker>& m) const {
  if (!r.contains("crack_stresses"))
    return;
  const nlohmann::json& c = r["crack_stresses"];
  auto add = [&](const char* stress, const char* strain, const char* label) {
    if (!r[stress].is_number() || !c[strain].is_number())
      return;
    const double eps = c[strain].get<double>();
    for (const LabSample& s : samples)
      if (s.axial_strain >= eps) {
        m.push_back({100 * eps, 1e-6 * s.axial_stress, label});
        return;
      }
  };
  add("crack_initiation_stress_Pa", "crack_initiation_axial_strain", "CI (crack count)");
  add("crack_initiation_stress_volumetric_Pa", "crack_initiation_volumetric_axial_strain",
      "CI (crack volumetric strain)");
  add("crack_damage_stress_Pa", "crack_damage_axial_strain", "CD (volume reversal)");
}

std::vector<SuiteProperty> CompressionTest::result_columns() const {
  using enum PropertyKind;
  return {{.name = "confinement_Pa", .label = "conf", .kind = Stress},
          {.name = "youngs_modulus_Pa", .label = "E", .kind = Modulus},
          {.name = "poisson_ratio", .label = "nu"},
          {.name = "peak_stress_Pa", .label = "peak", .kind = Stress},
          {.name = "peak_deviator_Pa", .label = "deviator", .kind = Stress}};
}

void CompressionTest::add_to_suite(const nlohmann::json& r, SuiteValues& v) const {
  v.series[kEnvelopeSigma3].push_back(json_number(r, "confinement_Pa", std::nan(""))); // UCS: 0
  v.series[kEnvelopeSigma1].push_back(json_number(r, "peak_stress_Pa", std::nan("")));
}

} // namespace rocklab
