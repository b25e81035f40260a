// The calibration method (docs/calibration.md): three stages that each move the parameters a
// property depends on most, so that few (expensive, noisy) evaluations are needed.
//   1 elastic: the moduli scale E (E is proportional to them at a fixed stiffness ratio), the
//     stiffness ratio sets nu (a secant search, monotonic);
//   2 strength scale: at fixed strength ratios all strengths scale together, so one factor,
//     target UCS / measured UCS, iterated to the tolerance;
//   3 ratios: the dimensionless targets (UCS/BTS, crack initiation/UCS, friction angle, ...) by a
//     derivative-free optimiser over the shape parameters (NLopt's BOBYQA), then stage 2 again.
// An evaluation is a callback (the caller runs tests, averages replicate seeds, caches). Units of
// the properties: SI; the parameters are the card's own.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace rocklab::calibration {

/// What a free parameter does, which decides its stage.
enum class Role {
  Modulus,        ///< scales every elastic modulus (several may share the role: moved together)
  StiffnessRatio, ///< sets Poisson's ratio
  Strength,       ///< scales every strength (several share the role: moved together)
  Shape,          ///< a ratio or fraction searched in stage 3
};

struct Param {
  std::string name;
  Role role = Role::Shape;
  double lo = 0, hi = 0; ///< bounds, lo < hi
  double value = 0;      ///< start, then the current value
};

/// A target: a measured property and its tolerance (relative, or absolute when `absolute`).
struct Target {
  std::string property; ///< e.g. "youngs_modulus_Pa", "poisson_ratio", "ucs_Pa", "ucs_over_bts"
  double value = 0;
  double tolerance = 0.05;
  bool absolute = false;
  double error(double measured) const; ///< signed error in tolerances (|e| <= 1: met)
};

// Which target each stage steers is the property's declared role (lab/property.hpp: the
// modulus and the stiffness ratio's target in stage 1, the strength scale's in stage 2; stage 3
// takes the rest, stress targets relative to the strength's).

/// Elastic and Strength need the tests that measure E, nu (short elastic loading) and the UCS;
/// Ratios and Final need every test a target names.
enum class Stage { Elastic, Strength, Ratios, Final };

using Measured = std::map<std::string, double>;
/// A measured property, NaN when the evaluation did not measure it.
double value_of(const Measured& m, const std::string& key);
/// Every target within its tolerance in `m`.
bool every_target_met(const std::vector<Target>& targets, const Measured& m);
/// A target is met only where its mean is within its tolerance and the mean's standard error is
/// at most half the tolerance: a mean whose noise is as large as the tolerance can sit inside it
/// by chance (a 2-seed campaign that read the UCS within 5 % at a 10 % standard error was 14 %
/// off on 12 fresh seeds). One seed (no standard error) confirms nothing.
bool target_confirmed(const Target& t, double mean, double se);
/// Every target confirmed in `m` (its standard errors under se_key).
bool every_target_confirmed(const std::vector<Target>& targets, const Measured& m);
/// The key under which an evaluation gives the number of seeds its means are over.
inline const char* const kSeedCount = "replicate_seeds";
/// Where Measured keeps the standard error of a property's mean over the seeds, beside the mean
/// (absent or NaN: one seed, no estimate of the noise).
inline std::string se_key(const std::string& property) {
  return property + ".se";
}
/// Runs the tests a stage needs for these parameter values (in the order of the Param list).
using Evaluate = std::function<Measured(const std::vector<double>& values, Stage stage)>;
/// Adds a replicate seed to every later evaluation; false when the budget allows no more.
using AddSeed = std::function<bool()>;

struct Record {
  int evaluation = 0;
  Stage stage = Stage::Elastic;
  std::vector<double> values;
  Measured measured;
};

struct Outcome {
  std::vector<Param> params; ///< final values
  Measured measured;         ///< at the final values (the last full evaluation)
  std::vector<Record> history;
  bool met = false; ///< every target within its tolerance
  /// What the method noticed on the way, for the report: e.g. a shape parameter that moved no
  /// steered property (inert for these targets: another parameter should be freed).
  std::vector<std::string> notes;
};

/// Evaluations per stage at most; polish: each of stages 1 and 2 again after stage 3. The
/// defaults add up to at most 36 with the final evaluation.
struct Budget {
  int elastic = 6, strength = 4, ratios = 20, polish = 3;
  /// Replicate seeds per evaluation at most, the file's and those added where the noise
  /// hides a miss (a file's 0 is read as its listed seeds, at least 6)
  int max_seeds = 0;
  /// Validation seeds: at least `validation_min`, at most `validation_max` (0: no validation)
  int validation_min = 6, validation_max = 12;
  /// Validations at most: after a failed one its seeds join the tuned ones and the stages go on
  /// from the fitted card (when any stage has a budget), then a new validation on fresh seeds
  int validation_rounds = 2;
  std::uint64_t validation_first = 1001; ///< fresh seeds from this one on
  bool sensitivity = true; ///< afterwards, one single-seed run per parameter (the report's table)
};

/// The stages. A steered target (E, nu, UCS) that misses by less than twice its standard error
/// is not stepped on: the same point is evaluated again with one more seed from `add_seed` while
/// that allows, and otherwise the stage leaves it and says so in the notes.
Outcome calibrate(std::vector<Param> params, const std::vector<Target>& targets,
                  const Evaluate& evaluate, const Budget& budget, const AddSeed& add_seed = {});

/// Name of a stage or role (reports, errors).
const char* stage_name(Stage s);
const char* role_name(Role r);

} // namespace rocklab::calibration
