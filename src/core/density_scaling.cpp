// Density scaling for quasi-static runs. The automatic time step is the smallest of the balls'
// own stable steps, sqrt(m / k_tran) and sqrt(I / k_rot) with the stiffness sums of their
// contacts (forces.cpp); in a bonded specimen a few small or well-connected grains set it. Raising
// the inertia of those grains (and only those) to what gives them the step of the chosen quantile
// lets the whole model take that step: fewer steps for the same loading, at the price of slower
// stress waves in the scaled grains, which a quasi-static test does not feel (docs/results.md,
// "Quasi-static accelerations", measures it). Units SI.
#include "core/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rocklab {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// A ball's own stable steps [s] (translation, rotation; infinite without stiffness).
struct OwnSteps {
  double tran = kInf, rot = kInf;
};

} // namespace

DensityScaling Model::scale_density(double quantile) {
  if (!(quantile >= 0 && quantile < 1))
    throw std::invalid_argument("density scaling: the quantile must be in [0, 1)");
  if (!initialized_)
    initialize();
  const std::size_t n = balls.size();
  // Back to the true inertia first (each ball keeps its kinetic energy). Factors left over from
  // before the balls changed are not in effect (density_scaled()): nothing to undo then.
  if (density_scaled())
    for (std::size_t i = 0; i < n; ++i) {
      balls.vel[i] *= std::sqrt(mass_scale_[i]);
      balls.spin[i] *= std::sqrt(inertia_scale_[i]);
    }
  mass_scale_.clear();
  inertia_scale_.clear();
  DensityScaling out;
  out.quantile = quantile;

  // The stiffness sums as sum_ball_forces forms them, from the last force update.
  std::vector<OwnSteps> own(n);
  for (std::size_t i = 0; i < n; ++i) {
    double k_tran = 0, k_rot = 0;
    for (std::int32_t a = adj_start_[i]; a < adj_start_[i + 1]; ++a) {
      const ContactOutput& c = outputs_[static_cast<std::size_t>(adj_items_[a] >> 1)];
      add_ball_stiffness(c.stiff, c.xc - balls.pos[i], k_tran, k_rot);
    }
    if (k_tran > 0)
      own[i].tran = std::sqrt(balls.mass[i] / k_tran);
    if (k_rot > 0)
      own[i].rot = std::sqrt(balls.inertia[i] / k_rot);
  }
  std::vector<double> steps;
  double before = kInf;
  for (std::size_t i = 0; i < n; ++i) {
    before = std::min({before, own[i].tran, own[i].rot});
    if (balls.clump[i] < 0 && std::isfinite(std::min(own[i].tran, own[i].rot)))
      steps.push_back(std::min(own[i].tran, own[i].rot));
  }
  if (quantile == 0 || steps.empty()) {
    dt_stiffness_ = before; // the next step is the true inertia's
    return out;
  }
  const auto k = static_cast<std::size_t>(quantile * static_cast<double>(steps.size() - 1));
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(k), steps.end());
  const double target = steps[k];

  mass_scale_.assign(n, 1.0);
  inertia_scale_.assign(n, 1.0);
  double after = kInf;
  for (std::size_t i = 0; i < n; ++i) {
    if (balls.clump[i] < 0) { // a clump's pebbles move with the clump's own inertia
      if (own[i].tran < target)
        mass_scale_[i] = (target / own[i].tran) * (target / own[i].tran);
      if (own[i].rot < target)
        inertia_scale_[i] = (target / own[i].rot) * (target / own[i].rot);
      if (mass_scale_[i] > 1 || inertia_scale_[i] > 1)
        ++out.scaled;
      out.max_factor = std::max({out.max_factor, mass_scale_[i], inertia_scale_[i]});
      balls.vel[i] /= std::sqrt(mass_scale_[i]);
      balls.spin[i] /= std::sqrt(inertia_scale_[i]);
    }
    after = std::min({after, own[i].tran * std::sqrt(mass_scale_[i]),
                      own[i].rot * std::sqrt(inertia_scale_[i])});
  }
  out.step_gain = std::isfinite(before) && before > 0 ? after / before : 1.0;
  dt_stiffness_ = after;
  return out;
}

} // namespace rocklab
