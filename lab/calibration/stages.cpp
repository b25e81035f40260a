#include "lab/calibration/stages.hpp"
#include "lab/calibration/noise.hpp"
#include "lab/property.hpp"

#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>

namespace rocklab::calibration {

double Target::error(double measured) const {
  if (!std::isfinite(measured))
    return std::numeric_limits<double>::infinity();
  return absolute ? (measured - value) / tolerance : (measured / value - 1) / tolerance;
}

double value_of(const Measured& m, const std::string& key) {
  const auto it = m.find(key);
  return it == m.end() ? std::nan("") : it->second;
}

bool every_target_met(const std::vector<Target>& targets, const Measured& m) {
  return std::all_of(targets.begin(), targets.end(), [&](const Target& t) {
    return std::abs(t.error(value_of(m, t.property))) <= 1;
  });
}

bool target_confirmed(const Target& t, double mean, double se) {
  return std::abs(t.error(mean)) <= 1 && std::isfinite(se) &&
         se <= 0.5 * tolerance_in_units(t) * (1 + 1e-12);
}

bool every_target_confirmed(const std::vector<Target>& targets, const Measured& m) {
  return std::all_of(targets.begin(), targets.end(), [&](const Target& t) {
    return target_confirmed(t, value_of(m, t.property), value_of(m, se_key(t.property)));
  });
}

const char* stage_name(Stage s) {
  switch (s) {
  case Stage::Elastic:
    return "elastic";
  case Stage::Strength:
    return "strength";
  case Stage::Ratios:
    return "ratios";
  case Stage::Final:
    return "final";
  }
  return "?";
}

const char* role_name(Role r) {
  switch (r) {
  case Role::Modulus:
    return "modulus";
  case Role::StiffnessRatio:
    return "stiffness_ratio";
  case Role::Strength:
    return "strength";
  case Role::Shape:
    return "shape";
  }
  return "?";
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

// A shape parameter's search coordinate in [0, 1] (logarithmic for positive bounds) and back.
double to_unit(const Param& q) {
  return q.lo > 0 ? std::log(q.value / q.lo) / std::log(q.hi / q.lo)
                  : (q.value - q.lo) / (q.hi - q.lo);
}
double from_unit(const Param& q, double x) {
  x = std::clamp(x, 0.0, 1.0);
  return q.lo > 0 ? q.lo * std::pow(q.hi / q.lo, x) : q.lo + x * (q.hi - q.lo);
}

// Inert shape parameters: a step of one shape parameter alone (BOBYQA's first points are such
// steps) that moves no scale-free target by a tenth of its tolerance. In the 2D granite and the 3D
// Berea the cohesion/tension ratio was (every joint breaks in tension), and COBYLA spent its
// budget on it; once every shape parameter has proved inert the stage stops.
struct InertWatch {
  std::vector<int> state; ///< per shape parameter: 0 unknown, 1 inert, 2 moves a target
  std::vector<double> prev_x, prev_e;

  explicit InertWatch(std::size_t n) : state(n, 0) {}
  /// After an evaluation at x (search coordinates) with these target errors (in tolerances).
  void step(const std::vector<double>& x, const std::vector<double>& e, const std::vector<Param>& p,
            const std::vector<std::size_t>& shape, std::vector<std::string>& notes) {
    if (!prev_x.empty()) {
      std::vector<std::size_t> moved;
      for (std::size_t k = 0; k < x.size(); ++k)
        if (std::abs(x[k] - prev_x[k]) >= 0.05)
          moved.push_back(k);
      double change = 0;
      for (std::size_t i = 0; i < e.size(); ++i)
        change = std::max(change, std::isfinite(e[i]) && std::isfinite(prev_e[i])
                                      ? std::abs(e[i] - prev_e[i])
                                      : kInf);
      if (moved.size() == 1 && state[moved[0]] != 2) {
        const Param& q = p[shape[moved[0]]];
        state[moved[0]] = change < 0.1 ? 1 : 2;
        if (change < 0.1)
          notes.push_back(q.name + " moved from " + num(from_unit(q, prev_x[moved[0]])) + " to " +
                          num(q.value) +
                          " and no scale-free target by a tenth of its tolerance (largest " +
                          num(change) + "): inert for these targets; free another parameter");
      }
    }
    prev_x = x;
    prev_e = e;
  }
  bool all_inert() const {
    return std::all_of(state.begin(), state.end(), [](int v) { return v == 1; });
  }
};

// Whether a target's property is a stress, as the test that measures it declares
// (lab/property.hpp).
bool is_stress(const std::string& property) {
  return property_kind(property) == PropertyKind::Stress;
}

// Each scale-free target's error in tolerances (a stress X as X / UCS against its target / the
// UCS target) and its standard error (the ratio's from both relative errors; 0 where a mean has
// no estimate of its noise).
std::vector<double> scale_free_errors(const Measured& m, const std::vector<const Target*>& free,
                                      const Target* tu, std::vector<double>& se) {
  std::vector<double> e;
  se.clear();
  const double u = value_of(m, tu->property);
  auto rel_se = [&](const std::string& key, double v) {
    const double s = value_of(m, se_key(key));
    return std::isfinite(s) && v != 0 ? s / std::abs(v) : 0.0;
  };
  for (const Target* t : free) {
    const double v = value_of(m, t->property);
    if (is_stress(t->property)) {
      Target r = *t;
      r.value = t->value / tu->value;
      e.push_back(r.error(v / u));
      se.push_back(std::hypot(rel_se(t->property, v), rel_se(tu->property, u)) * std::abs(v / u) /
                   (r.value * r.tolerance));
    } else {
      e.push_back(t->error(v));
      const double s = value_of(m, se_key(t->property));
      se.push_back(std::isfinite(s) ? s / (t->absolute ? 1.0 : t->value) / t->tolerance : 0.0);
    }
  }
  return e;
}

// The sum of squared errors, its worst term, and its standard error (an error e with standard
// error s gives e^2 the variance 4 e^2 s^2 + 2 s^4).
double misfit(const std::vector<double>& errs, const std::vector<double>& se, double& worst,
              double& f_se) {
  double sum = 0, var = 0;
  worst = 0;
  for (std::size_t i = 0; i < errs.size(); ++i) {
    const double e = errs[i], s = se[i];
    sum += std::isfinite(e) ? e * e : 1e6;
    worst = std::max(worst, std::abs(e));
    if (std::isfinite(e))
      var += 4 * e * e * s * s + 2 * s * s * s * s;
  }
  f_se = std::sqrt(var);
  return sum;
}

struct Campaign {
  std::vector<Param>& p;
  const std::vector<Target>& targets;
  const Evaluate& evaluate;
  const AddSeed& add_seed;
  Outcome& out;
  int since_full = 0;               ///< evaluations since the last one that measured everything
  bool reseed = false;              ///< a seed was added: the same point is measured again
  std::vector<const Target*> noisy; ///< targets whose noise the notes name

  /// The target whose property plays `r` in the stages, nullptr where none does.
  const Target* target(CalibrationRole r) const {
    for (const Target& t : targets)
      if (property_role(t.property) == r)
        return &t;
    return nullptr;
  }
  bool has(Role r) const {
    return std::any_of(p.begin(), p.end(), [&](const Param& x) { return x.role == r; });
  }
  Measured run(Stage s) {
    std::vector<double> v;
    for (const Param& x : p)
      v.push_back(x.value);
    // The same point again (a stage ending where the next begins): the last measurement serves
    // when its tests cover this stage's (Elastic and Strength run the same tests).
    if (!reseed && !out.history.empty() && out.history.back().values == v) {
      const Stage last = out.history.back().stage;
      const bool full = last == Stage::Ratios || last == Stage::Final;
      if (full || (s == Stage::Elastic || s == Stage::Strength))
        return out.history.back().measured;
    }
    reseed = false;
    Measured m = evaluate(v, s);
    out.history.push_back({static_cast<int>(out.history.size()) + 1, s, v, m});
    out.measured = m;
    since_full = (s == Stage::Ratios || s == Stage::Final) ? 0 : since_full + 1;
    return m;
  }
  /// Multiplies every parameter of a role by f, within its bounds.
  void scale(Role r, double f) {
    for (Param& x : p)
      if (x.role == r)
        x.value = std::clamp(x.value * f, x.lo, x.hi);
  }
  bool met(const Target* t, const Measured& m) const {
    return !t || std::abs(t->error(value_of(m, t->property))) <= 1;
  }
  /// A miss of `t` smaller than twice its standard error: no step on it. True when a seed was
  /// added (measure the same point again); false with a note when the budget allows no more.
  bool hidden_by_noise(const Target* t, const Measured& m, bool& step) {
    step = true;
    const double v = value_of(m, t->property), se = value_of(m, se_key(t->property));
    if (!within_noise(*t, v, se))
      return false;
    step = false;
    if (add_seed && add_seed()) {
      reseed = true;
      return true;
    }
    if (std::find(noisy.begin(), noisy.end(), t) != noisy.end())
      return false; // said already
    noisy.push_back(t);
    out.notes.push_back(t->property + " " + num(v) + " misses " + num(t->value) + " by " +
                        num(t->error(v)) + " tolerances, within twice its standard error (" +
                        num(se) +
                        "): more seeds than the budget's are needed to tell; not "
                        "stepped on");
    return false;
  }

  void elastic(int budget);
  void strength(int budget);
  void ratios(int budget);
  void confirm();
};

// The final evaluation's targets that are within their tolerance but whose standard error is
// above half of it: the same card on one more seed at a time while the budget allows; a target
// still unconfirmed then is named with the seeds it would need, (se / half tolerance)^2 times the
// seeds run.
void Campaign::confirm() {
  auto unconfirmed = [&] {
    std::vector<const Target*> u;
    for (const Target& t : targets) {
      const double v = value_of(out.measured, t.property);
      if (std::abs(t.error(v)) <= 1 &&
          !target_confirmed(t, v, value_of(out.measured, se_key(t.property))))
        u.push_back(&t);
    }
    return u;
  };
  for (std::vector<const Target*> u = unconfirmed(); !u.empty(); u = unconfirmed()) {
    if (add_seed && add_seed()) {
      reseed = true;
      run(Stage::Final);
      continue;
    }
    const double n = value_of(out.measured, kSeedCount);
    for (const Target* t : u) {
      const double se = value_of(out.measured, se_key(t->property));
      const double half = 0.5 * tolerance_in_units(*t);
      std::string need = "more than one seed";
      if (std::isfinite(se) && std::isfinite(n))
        need = "about " + num(std::ceil(n * (se / half) * (se / half))) + " seeds";
      const std::string why =
          std::isfinite(se)
              ? "its standard error " + num(se) + " is above half its tolerance (" + num(half) + ")"
              : std::string("one seed gives no standard error");
      out.notes.push_back(t->property + " " + num(value_of(out.measured, t->property)) +
                          " is within its tolerance of " + num(t->value) + " but not confirmed: " +
                          why + "; it needs " + need + ", more than the budget's");
    }
    return;
  }
}

// Stage 1. E: the moduli times target/measured. nu: a secant search on log(stiffness ratio),
// nu rising with the ratio (0.15 per e-fold until two points give the slope), steps at most a
// factor 2. The seeds' scatter of nu (+-0.005 in a 3-seed mean) swamps a secant over a short
// step: in the 2D acceptance run two evaluations 4 % apart gave nu 0.2494 and 0.2498, and that
// near-flat secant doubled a stiffness ratio within 4 % of its target. So the secant is taken
// only between points at least 0.1 apart in log(ratio) (the older point is kept until then) and
// held within [0.05, 0.5] per e-fold (bonded materials measure 0.1-0.2).
void Campaign::elastic(int budget) {
  const Target* tE = target(CalibrationRole::Modulus);
  const Target* tn = target(CalibrationRole::StiffnessRatio);
  const bool steer_e = tE && has(Role::Modulus), steer_n = tn && has(Role::StiffnessRatio);
  if (!steer_e && !steer_n)
    return;
  double prev_k = std::nan(""), prev_n = std::nan(""), slope = 0.15;
  for (int i = 0; i < budget; ++i) {
    const Measured m = run(Stage::Elastic);
    const bool ok_e = !steer_e || met(tE, m), ok_n = !steer_n || met(tn, m);
    if (ok_e && ok_n)
      return;
    bool step_e = false, step_n = false;
    if ((!ok_e && hidden_by_noise(tE, m, step_e)) || (!ok_n && hidden_by_noise(tn, m, step_n)))
      continue; // one more seed: the same point again
    if (!step_e && !step_n)
      return;
    if (step_n) {
      const auto k = std::find_if(p.begin(), p.end(),
                                  [](const Param& x) { return x.role == Role::StiffnessRatio; });
      const double nu = value_of(m, tn->property), lk = std::log(k->value);
      if (!std::isfinite(prev_n) || std::abs(lk - prev_k) >= 0.1) {
        if (std::isfinite(prev_n)) {
          const double secant = (nu - prev_n) / (lk - prev_k);
          slope = secant > 0 ? std::clamp(secant, 0.05, 0.5) : 0.15; // falling: noise
        }
        prev_k = lk;
        prev_n = nu;
      }
      const double step = std::clamp((tn->value - nu) / slope, -std::log(2.0), std::log(2.0));
      scale(Role::StiffnessRatio, std::exp(step));
    }
    const double e = step_e ? value_of(m, tE->property) : 0.0;
    if (step_e && e > 0)
      scale(Role::Modulus, std::clamp(tE->value / e, 0.25, 4.0));
  }
}

// Stage 2: all strengths times target UCS / measured UCS.
void Campaign::strength(int budget) {
  const Target* tu = target(CalibrationRole::Strength);
  if (!tu || !has(Role::Strength))
    return;
  for (int i = 0; i < budget; ++i) {
    const Measured m = run(Stage::Strength);
    const double u = value_of(m, tu->property);
    if (met(tu, m) || !(u > 0))
      return;
    bool step = false;
    if (hidden_by_noise(tu, m, step))
      continue;
    if (!step)
      return;
    scale(Role::Strength, std::clamp(tu->value / u, 0.25, 4.0));
  }
}

// Stage 3's best evaluated point. One that meets every scale-free target (where the search stops)
// beats one with a smaller sum of squared errors that misses one: the Berea campaign kept a point
// with errors (0.06, -1.18) over the one with (-0.8, -0.92) that met both, and polished the wrong
// card. Between two that both meet or both miss, a smaller sum replaces the kept point only when
// it is smaller by more than twice the standard error of the difference: a step within the seeds'
// noise is not progress (BOBYQA itself still sees every mean), and `ties` counts those.
struct BestPoint {
  double f = kInf; ///< sum of squared errors [tolerances^2]
  double se = 0;   ///< its standard error from the seeds' scatter [tolerances^2]
  bool met = false;
  int ties = 0; ///< smaller sums within the noise of the kept one
  std::vector<double> values;
  void offer(double f_new, double se_new, bool met_new, const std::vector<Param>& p) {
    if (met_new == met && f_new < f && f - f_new <= 2 * std::hypot(se, se_new)) {
      ++ties;
      return;
    }
    if (!((met_new && !met) || (met_new == met && f_new < f)))
      return;
    f = f_new;
    se = se_new;
    met = met_new;
    values.clear();
    for (const Param& q : p)
      values.push_back(q.value);
  }
};

// Stage 3: the scale-free targets (every target but E and the UCS; a stress target X becomes
// X / UCS against its target / the UCS target) by BOBYQA over the shape parameters, in [0, 1]
// coordinates (logarithmic for positive bounds). The best evaluated point is kept, never a model
// prediction: the first that meets every scale-free target (the search stops there), else the
// smallest sum of squared errors.
void Campaign::ratios(int budget) {
  std::vector<std::size_t> shape;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p[i].role == Role::Shape)
      shape.push_back(i);
  const Target* tu = target(CalibrationRole::Strength);
  std::vector<const Target*> free;
  for (const Target& t : targets) {
    const CalibrationRole r = property_role(t.property);
    if (r != CalibrationRole::Modulus && r != CalibrationRole::Strength &&
        (!is_stress(t.property) || tu))
      free.push_back(&t);
  }
  if (shape.empty() || free.empty() || budget < 1)
    return;
  BestPoint best;
  int used = 0;
  const std::size_t n = shape.size();
  InertWatch inert(n);
  nlopt::opt opt(n == 1 ? nlopt::LN_COBYLA : nlopt::LN_BOBYQA, static_cast<unsigned>(n));
  opt.set_lower_bounds(std::vector<double>(n, 0.0));
  opt.set_upper_bounds(std::vector<double>(n, 1.0));
  opt.set_maxeval(budget);
  opt.set_initial_step(0.15);
  opt.set_xtol_abs(1e-3);
  // NLopt's C++ wrapper swallows an exception thrown by the objective (it becomes a generic
  // "nlopt failure"), so an interrupt or a rejected test is kept here and rethrown afterwards.
  std::exception_ptr thrown;
  auto objective = [&](const std::vector<double>& x) {
    for (std::size_t k = 0; k < n; ++k)
      p[shape[k]].value = from_unit(p[shape[k]], x[k]);
    Measured m;
    try {
      m = run(Stage::Ratios);
    } catch (...) {
      thrown = std::current_exception();
      opt.force_stop();
      return HUGE_VAL;
    }
    ++used;
    std::vector<double> se;
    const std::vector<double> errs = scale_free_errors(m, free, tu, se);
    double worst, f_se;
    const double f = misfit(errs, se, worst, f_se);
    inert.step(x, errs, p, shape, out.notes);
    best.offer(f, f_se, worst <= 1, p);
    const bool all_inert = inert.all_inert();
    if (all_inert)
      out.notes.push_back("stage 3 stopped: every shape parameter is inert");
    if (worst <= 1 || used >= budget || all_inert)
      opt.force_stop();
    return f;
  };
  using Fn = decltype(objective);
  opt.set_min_objective([](const std::vector<double>& x, std::vector<double>&,
                           void* data) { return (*static_cast<Fn*>(data))(x); },
                        &objective);
  std::vector<double> x(n);
  for (std::size_t k = 0; k < n; ++k)
    x[k] = to_unit(p[shape[k]]);
  double f = 0;
  try {
    opt.optimize(x, f);
  } catch (const nlopt::forced_stop&) {
  } catch (const std::exception&) {
    // roundoff-limited or similar: the best point so far stands
  }
  if (thrown)
    std::rethrow_exception(thrown);
  if (best.ties > 0)
    out.notes.push_back("stage 3: " + std::to_string(best.ties) +
                        " point(s) had a smaller sum of squared errors than the kept one by less "
                        "than twice the standard error of the difference (the seeds' noise, not "
                        "progress); the kept point stands (sum " +
                        num(best.f) + " +- " + num(best.se) + " tolerances^2)");
  for (std::size_t i = 0; i < p.size() && best.values.size() == p.size(); ++i)
    p[i].value = best.values[i];
}

} // namespace

Outcome calibrate(std::vector<Param> params, const std::vector<Target>& targets,
                  const Evaluate& evaluate, const Budget& budget, const AddSeed& add_seed) {
  Outcome out;
  Campaign c{params, targets, evaluate, add_seed, out, 0, false, {}};
  c.elastic(budget.elastic);
  c.strength(budget.strength);
  c.ratios(budget.ratios);
  // The ratios moved the strengths and moduli a little: scale them back, then measure everything.
  c.elastic(budget.polish);
  c.strength(budget.polish);
  if (c.since_full > 0 || out.history.empty())
    c.run(Stage::Final);
  if (budget.elastic + budget.strength + budget.ratios + budget.polish > 0)
    c.confirm(); // (a validation-only campaign tunes nothing: its validation judges the card)
  out.params = params;
  out.met = every_target_confirmed(targets, out.measured);
  return out;
}

} // namespace rocklab::calibration
