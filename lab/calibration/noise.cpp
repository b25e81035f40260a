#include "lab/calibration/noise.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rocklab::calibration {

double standard_error(double sd, int n) {
  return n >= 2 && std::isfinite(sd) ? sd / std::sqrt(static_cast<double>(n)) : std::nan("");
}

double tolerance_in_units(const Target& t) {
  return t.absolute ? t.tolerance : t.tolerance * std::abs(t.value);
}

int seeds_needed(const Target& t, double sd, double fraction) {
  if (!std::isfinite(sd))
    return -1;
  const double allowed = fraction * tolerance_in_units(t);
  const double n = std::ceil((sd / allowed) * (sd / allowed) - 1e-9);
  return static_cast<int>(std::clamp(n, 2.0, 1e6));
}

int validation_seed_count(const std::vector<Target>& targets, const Measured& sd, int min_seeds,
                          int max_seeds) {
  const int most = std::max(min_seeds, max_seeds);
  int n = min_seeds;
  for (const Target& t : targets) {
    const int need = seeds_needed(t, value_of(sd, t.property));
    n = std::max(n, need < 0 ? most : need); // an unknown scatter: as many as allowed
  }
  return std::min(n, most);
}

Measured known_scatter(const Measured& sd, const Measured& se) {
  Measured out;
  for (const auto& [k, v] : sd)
    out[k] = std::isfinite(value_of(se, k)) ? v : std::nan("");
  return out;
}

std::vector<std::uint64_t> fresh_seeds(std::uint64_t first, int count,
                                       const std::vector<std::uint64_t>& used) {
  std::vector<std::uint64_t> out;
  for (std::uint64_t s = first; static_cast<int>(out.size()) < count; ++s)
    if (std::find(used.begin(), used.end(), s) == used.end())
      out.push_back(s);
  return out;
}

bool within_noise(const Target& t, double measured, double se) {
  return std::isfinite(se) && std::abs(measured - t.value) < 2 * se;
}

std::vector<ParamUncertainty> parameter_uncertainty(const std::vector<std::vector<double>>& s,
                                                    const std::vector<double>& rel_se) {
  const std::size_t np = s.size();
  std::vector<std::size_t> rows; // the targets that can be used
  for (std::size_t j = 0; j < rel_se.size(); ++j) {
    bool ok = std::isfinite(rel_se[j]) && rel_se[j] > 0;
    for (std::size_t i = 0; i < np && ok; ++i)
      ok = j < s[i].size() && std::isfinite(s[i][j]);
    if (ok)
      rows.push_back(j);
  }
  std::vector<ParamUncertainty> out(np);
  if (np == 0)
    return out; // no free parameter: nothing to be uncertain about (and no matrix to decompose)
  const double inf = std::numeric_limits<double>::infinity();
  if (rows.empty()) {
    for (ParamUncertainty& u : out)
      u = {inf, 1.0, false};
    return out;
  }
  // The weighted Jacobian: each target's row divided by its relative standard error.
  Eigen::MatrixXd j(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(np));
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t i = 0; i < np; ++i)
      j(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(i)) =
          s[i][rows[r]] / rel_se[rows[r]];
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(j, Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  const Eigen::MatrixXd& v = svd.matrixV();
  const double floor = 1e-9 * (sv.size() > 0 ? sv(0) : 0.0);
  for (std::size_t i = 0; i < np; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    double var = 0, blind = 0;
    for (Eigen::Index k = 0; k < v.cols(); ++k) {
      const double vik = v(ii, k);
      if (k < sv.size() && sv(k) > floor)
        var += vik * vik / (sv(k) * sv(k));
      else
        blind += vik * vik; // a direction no target sees
    }
    ParamUncertainty& u = out[i];
    u.blind_share = std::sqrt(blind);
    u.sd_ln = u.blind_share >= 0.1 ? inf : std::sqrt(var);
    u.identifiable = u.blind_share < 0.1 && u.sd_ln <= 0.5;
  }
  return out;
}

} // namespace rocklab::calibration
