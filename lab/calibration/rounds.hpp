// A calibration judged on fresh seeds, and what follows a failed judgement (docs/calibration.md,
// "Noise and validation"): the stages fit the card on the replicate seeds, a validation measures
// it on seeds it was never tuned on, and where that misses a target (or cannot confirm one), the
// validation's seeds join the tuned ones, the stages go on from the fitted card with that evidence
// and a new validation on other fresh seeds judges the result, within the budget's rounds. Units
// SI.
#pragma once

#include "lab/calibration/stages.hpp"

#include <cstdint>
#include <functional>
#include <vector>

namespace rocklab::calibration {

/// One validation: the fitted card's means over fresh seeds.
struct ValidationRun {
  std::vector<std::uint64_t> seeds;
  Measured mean, sd, se;
  int rejected = 0; ///< tests not valid (validity_rules()), left out of the means resting on them
};
/// Measures the card with these parameter values on fresh seeds.
using Validate = std::function<ValidationRun(const std::vector<double>& values)>;
/// Makes these seeds replicate seeds of every later evaluation.
using Adopt = std::function<void(const std::vector<std::uint64_t>& seeds)>;

struct Validated {
  Outcome outcome;          ///< the stages' (every round's evaluations and notes)
  ValidationRun validation; ///< the last validation (no seeds: none was run)
  int rounds = 0;           ///< validations run
  bool met = false;         ///< every target confirmed on the last validation's seeds
};

/// calibrate(), then up to budget.validation_rounds validations (none when validation_max is 0
/// or `validate` is empty); after a failed one, when any stage has a budget, its seeds are
/// adopted and calibrate() goes on from the fitted card.
Validated calibrate_and_validate(std::vector<Param> params, const std::vector<Target>& targets,
                                 const Evaluate& evaluate, const Budget& budget,
                                 const AddSeed& add_seed, const Validate& validate,
                                 const Adopt& adopt);

} // namespace rocklab::calibration
