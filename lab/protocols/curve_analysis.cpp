#include "lab/protocols/curve_analysis.hpp"

#include "lab/frame/elastic_fit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rocklab {

namespace {

std::string fmt(const char* f, double a, double b = 0, double c = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c);
  return buf;
}

// Crack initiation by count: the first sample at which the cumulative crack count reaches
// kOnsetCrackFraction of the count at the peak (at least two cracks, so that one early break
// from locked-in stresses does not count).
std::optional<CurvePoint> count_onset(const CurveInput& in) {
  if (in.cracks.empty())
    return std::nullopt;
  const std::int64_t at_peak = in.cracks.back();
  const auto need = std::max<std::int64_t>(
      2, static_cast<std::int64_t>(std::ceil(kOnsetCrackFraction * static_cast<double>(at_peak))));
  for (std::size_t i = 0; i < in.samples.size(); ++i)
    if (in.cracks[i] >= need)
      return CurvePoint{in.samples[i].load, in.samples[i].axial_strain};
  return std::nullopt;
}

// The elastic window: from kWindowStart of the peak (deviator above the seating load) to the crack
// onset or kWindowEnd of the peak, whichever is lower; at least 8 samples, else the ISRM-like
// window [kWindowStart, kWindowEnd] with a warning.
void elastic_window(const CurveInput& in, CurveAnalysis& a) {
  const double dq = in.peak - in.load_ref;
  const double lo = in.load_ref + kWindowStart * dq, end = in.load_ref + kWindowEnd * dq;
  const double hi = a.ci_count ? std::min(end, a.ci_count->load) : end;
  ElasticFit fit = fit_window(in.samples, lo, hi);
  a.before_cracking = true;
  a.window_lo = lo;
  a.window_hi = hi;
  if (fit.points < 8 || hi <= lo) {
    fit = fit_window(in.samples, lo, end);
    a.before_cracking = false;
    a.window_hi = end;
    a.warnings.push_back(fmt("no linear window before crack onset (cracking began at %.0f %% of "
                             "the peak): E and nu are fitted over %.0f-%.0f %% of the peak and "
                             "include crack deformation",
                             100 * (a.ci_count ? (a.ci_count->load - in.load_ref) / dq : 0.0),
                             100 * kWindowStart, 100 * kWindowEnd));
  }
  a.youngs_modulus = fit.youngs_modulus;
  a.poisson_ratio = fit.poisson_ratio;
  a.r2 = fit.r2;
  a.points = fit.points;
}

// Martin & Chandler (1994): crack volumetric strain = measured volumetric strain - the elastic
// part, (1 - 2 nu) q / E in 3D and (1 - nu) q / E in 2D (area strain), q the deviator above the
// seating load. Crack initiation: where it leaves zero for good, i.e. the last sample with a
// dilation smaller than kVolumetricTolerance (0.5 %) of the elastic axial strain at the peak
// (on the 2D granite the crack volumetric strain scatters by 0.1 % of it before any crack). Crack
// damage: the reversal of the volumetric strain (its largest compaction before the peak).
void volumetric_stresses(const CurveInput& in, CurveAnalysis& a) {
  const std::vector<LabSample>& s = in.samples;
  if (s.size() < 3 || !(a.youngs_modulus > 0))
    return;
  const double lat = in.dim == 2 ? 1.0 : 2.0;
  const double c = in.dim == 2 ? 1 - a.poisson_ratio : 1 - 2 * a.poisson_ratio;
  const double tol = kVolumetricTolerance * (in.peak - in.load_ref) / a.youngs_modulus;
  std::size_t last_ok = 0, vmax = 0;
  auto vol = [&](const LabSample& x) { return x.axial_strain + lat * x.lateral_strain; };
  a.crack_volumetric_strain.resize(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    const double ev = vol(s[i]);
    a.crack_volumetric_strain[i] = ev - c * (s[i].load - in.load_ref) / a.youngs_modulus;
    if (a.crack_volumetric_strain[i] >= -tol)
      last_ok = i;
    if (ev > vol(s[vmax]))
      vmax = i;
  }
  if (last_ok + 1 < s.size())
    a.ci_volumetric = CurvePoint{s[last_ok].load, s[last_ok].axial_strain};
  if (vmax + 1 < s.size())
    a.cd = CurvePoint{s[vmax].load, s[vmax].axial_strain};
}

// Physically impossible or doubtful values are named, never reported silently.
void check(const CurveInput& in, CurveAnalysis& a) {
  const double nu_max = in.dim == 2 ? 1.0 : 0.5;
  const char* range = in.dim == 2 ? "(-1, 1) in 2D" : "(-1, 0.5) in 3D";
  auto check_nu = [&](const char* key, double nu, const char* why) {
    if (!(nu > -1 && nu < nu_max))
      a.warnings.push_back(std::string(key) + " = " + fmt("%.3g", nu) + " is outside " + range +
                           ": " + why);
  };
  check_nu("poisson_ratio", a.poisson_ratio,
           "the lateral strain of the elastic window is not elastic (see elastic_fit)");
  check_nu("poisson_ratio_tangent50", a.poisson50,
           "over 40-60 % of the peak the lateral strain is dominated by crack dilation, not an "
           "elastic constant; poisson_ratio is the linear-window value");
  if (!(a.youngs_modulus > 0))
    a.warnings.push_back("youngs_modulus_Pa is not positive: no elastic loading branch");
  if (a.before_cracking && a.r2 < 0.98)
    a.warnings.push_back(fmt("the elastic window is not linear (r2 = %.3f)", a.r2));
  if (a.tangent50 < 0.9 * a.secant50)
    a.warnings.push_back(fmt("the tangent modulus at 50 %% of the peak (%.3g GPa) is far below "
                             "the secant (%.3g GPa): cracking softens the curve before 50 %% of "
                             "the peak; youngs_modulus_Pa (%.3g GPa) is the linear-window value",
                             1e-9 * a.tangent50, 1e-9 * a.secant50, 1e-9 * a.youngs_modulus));
}

} // namespace

CurveAnalysis analyse_curve(const CurveInput& in) {
  CurveAnalysis a;
  if (in.samples.empty() || !(in.peak > in.load_ref))
    return a;
  a.ci_count = count_onset(in);
  elastic_window(in, a);
  const ElasticFit t50 = fit_window(in.samples, in.load_ref + 0.4 * (in.peak - in.load_ref),
                                    in.load_ref + 0.6 * (in.peak - in.load_ref));
  a.tangent50 = t50.youngs_modulus;
  a.poisson50 = t50.poisson_ratio;
  for (const LabSample& s : in.samples)
    if (s.load >= in.load_ref + 0.5 * (in.peak - in.load_ref) && s.axial_strain > 0) {
      a.secant50 = (s.load - in.load_ref) / s.axial_strain;
      break;
    }
  volumetric_stresses(in, a);
  check(in, a);
  return a;
}

void write_curve_results(const CurveAnalysis& a, double peak, nlohmann::json& r) {
  // Not positive: no elastic loading branch (warned); never reported as a modulus of 0.
  r["youngs_modulus_Pa"] =
      a.youngs_modulus > 0 ? nlohmann::json(a.youngs_modulus) : nlohmann::json(nullptr);
  r["poisson_ratio"] = a.poisson_ratio;
  r["youngs_modulus_secant_Pa"] = a.secant50;
  r["youngs_modulus_tangent50_Pa"] = a.tangent50;
  r["poisson_ratio_tangent50"] = a.poisson50;
  r["elastic_fit"] = {
      {"method", "least squares of the deviator and of the lateral strain against the axial "
                 "strain over the linear part of the loading branch: from 5 % of the peak "
                 "deviator (above the seating load) to the crack onset (crack count at 1 % of its "
                 "value at the peak) or 50 % of the peak, whichever is lower"},
      {"window_Pa", {a.window_lo, a.window_hi}},
      {"points", a.points},
      {"r2", a.r2},
      {"before_crack_onset", a.before_cracking},
      {"secant", "deviator over axial strain at 50 % of the peak (ISRM)"},
      {"tangent50", "least squares over 40-60 % of the peak (ISRM); includes cracking when it "
                    "starts earlier"}};
  auto point = [](const std::optional<CurvePoint>& p) {
    return p ? nlohmann::json(p->load) : nlohmann::json(nullptr);
  };
  auto ratio = [&](const std::optional<CurvePoint>& p) {
    return p && peak > 0 ? nlohmann::json(p->load / peak) : nlohmann::json(nullptr);
  };
  auto strain = [](const std::optional<CurvePoint>& p) {
    return p ? nlohmann::json(p->axial_strain) : nlohmann::json(nullptr);
  };
  r["crack_initiation_stress_Pa"] = point(a.ci_count);
  r["crack_initiation_stress_volumetric_Pa"] = point(a.ci_volumetric);
  r["crack_damage_stress_Pa"] = point(a.cd);
  r["crack_stresses"] = {
      {"units", "deviator stress [Pa] (UCS: the axial stress); ratios to the peak deviator"},
      {"crack_initiation_ratio", ratio(a.ci_count)},
      {"crack_initiation_volumetric_ratio", ratio(a.ci_volumetric)},
      {"crack_damage_ratio", ratio(a.cd)},
      {"crack_initiation_axial_strain", strain(a.ci_count)},
      {"crack_initiation_volumetric_axial_strain", strain(a.ci_volumetric)},
      {"crack_damage_axial_strain", strain(a.cd)},
      {"methods",
       {{"crack_initiation", "crack count leaving its background: the first sample with at least "
                             "1 % of the cracks counted at the peak (and at least 2)"},
        {"crack_initiation_volumetric",
         "Martin & Chandler (1994): where the crack volumetric strain (measured minus the "
         "elastic (1 - 2 nu) q / E, in 2D (1 - nu) q / E) leaves zero for good (dilation above "
         "0.5 % of the elastic axial strain at the peak)"},
        {"crack_damage", "volumetric-strain reversal: the largest volumetric compaction before "
                         "the peak (null when the volume still decreases at the peak)"}}}};
  for (const std::string& w : a.warnings)
    r["warnings"].push_back(w);
}

} // namespace rocklab
