#include "lab/calibration/rounds.hpp"
#include "lab/calibration/noise.hpp"

#include <cmath>
#include <cstdio>
#include <string>

namespace rocklab::calibration {

namespace {

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

std::vector<double> values_of(const std::vector<Param>& p) {
  std::vector<double> v;
  for (const Param& x : p)
    v.push_back(x.value);
  return v;
}

Measured with_se(const ValidationRun& v) {
  Measured m = v.mean;
  for (const auto& [k, se] : v.se)
    m[se_key(k)] = se;
  return m;
}

// The targets a validation missed or could not confirm, as "name (error in tolerances, or its
// standard error against half the tolerance)".
std::string misses(const std::vector<Target>& targets, const ValidationRun& v) {
  std::string s;
  for (const Target& t : targets) {
    const double m = value_of(v.mean, t.property), se = value_of(v.se, t.property);
    if (target_confirmed(t, m, se))
      continue;
    s += (s.empty() ? "" : ", ") + t.property + " ";
    if (!std::isfinite(m))
      s += "not measured";
    else if (std::abs(t.error(m)) > 1)
      s += num(t.error(m)) + " tolerances off";
    else
      s += "within but its standard error " + num(se) + " above half its tolerance";
    const int need = seeds_needed(t, value_of(v.sd, t.property));
    if (need > 0 && std::isfinite(se) && se > 0.5 * tolerance_in_units(t))
      s += " (needs " + std::to_string(need) + " seeds)";
  }
  return s;
}

std::string seed_range(const std::vector<std::uint64_t>& s) {
  if (s.empty())
    return "none";
  return std::to_string(s.front()) + (s.size() > 1 ? "-" + std::to_string(s.back()) : "");
}

} // namespace

Validated calibrate_and_validate(std::vector<Param> params, const std::vector<Target>& targets,
                                 const Evaluate& evaluate, const Budget& budget,
                                 const AddSeed& add_seed, const Validate& validate,
                                 const Adopt& adopt) {
  Validated v;
  v.outcome = calibrate(params, targets, evaluate, budget, add_seed);
  if (budget.validation_max <= 0 || !validate)
    return v;
  const bool can_step =
      budget.elastic + budget.strength + budget.ratios + budget.polish > 0 && adopt;
  for (;;) {
    v.validation = validate(values_of(v.outcome.params));
    ++v.rounds;
    v.met = every_target_confirmed(targets, with_se(v.validation));
    if (v.met)
      break;
    const std::string what = "validation " + std::to_string(v.rounds) + " on seeds " +
                             seed_range(v.validation.seeds) + ": " + misses(targets, v.validation);
    if (v.rounds >= budget.validation_rounds || !can_step) {
      v.outcome.notes.push_back(what + "; " +
                                (can_step ? "the budget's validation rounds are spent"
                                          : "no stage has a budget to step on it") +
                                ": the card is not confirmed on fresh seeds");
      break;
    }
    v.outcome.notes.push_back(what + "; those seeds join the tuned ones and the stages go on "
                                     "from the fitted card");
    adopt(v.validation.seeds);
    Outcome more = calibrate(v.outcome.params, targets, evaluate, budget, add_seed);
    const int done = static_cast<int>(v.outcome.history.size());
    for (Record& r : more.history) {
      r.evaluation += done;
      v.outcome.history.push_back(std::move(r));
    }
    for (std::string& n : more.notes)
      v.outcome.notes.push_back(std::move(n));
    v.outcome.params = std::move(more.params);
    v.outcome.measured = std::move(more.measured);
    v.outcome.met = more.met;
  }
  return v;
}

} // namespace rocklab::calibration
