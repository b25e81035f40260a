// What a calibration leaves for its user to read: report.md (targets against the achieved mean ±
// sd, the parameters, the sensitivity at the optimum, the cost), convergence.csv and
// convergence.svg (each target's error in tolerances against the evaluation). Units SI.
#pragma once

#include "lab/calibration/calibration_file.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace rocklab::calibration {

/// d ln(property) / d ln(parameter) at the optimum, by one-sided differences on one replicate
/// seed (the same packing in both runs, so the packing's noise cancels).
struct Sensitivity {
  std::vector<double> step;             ///< relative step of each parameter (e.g. +0.1, -0.1)
  std::vector<std::vector<double>> per; ///< [parameter][target]
  std::uint64_t seed = 0;
};

struct ReportInput {
  const CalibrationFile* file = nullptr;
  const Outcome* outcome = nullptr;
  Measured sd;   ///< over the seeds, at the final evaluation
  Measured se;   ///< standard error of the final evaluation's means (NaN: one seed)
  int seeds = 0; ///< replicate seeds of the final evaluation
  int rejected = 0, validation_rejected = 0; ///< tests not valid (validity_rules()), left out
  /// The fitted card on fresh seeds it was never tuned on (empty: no validation was run).
  std::vector<std::uint64_t> validation_seeds;
  int validation_rounds = 0; ///< validations run (the last one's seeds and means are these)
  Measured validation_mean, validation_sd, validation_se;
  Sensitivity sensitivity;
  std::vector<std::string> final_folders; ///< the final evaluation's suites, one per seed
  int suites_run = 0, suites_cached = 0;
  double wall_seconds = 0, cpu_seconds = 0;
};

/// The worst |error| in tolerances over the targets this evaluation measured (a test that gave
/// no value, NaN, counts as infinite).
double worst_error(const std::vector<Target>& targets, const Measured& m);
std::string convergence_csv(const CalibrationFile& c, const Outcome& out);
/// Each target's |error| in tolerances against the evaluation; with `validation` (the fitted
/// card's means on `validation_seeds` fresh seeds) one more point after the last evaluation, so
/// the step from the tuned seeds to fresh ones shows.
std::string convergence_svg(const CalibrationFile& c, const Outcome& out,
                            const Measured* validation = nullptr, std::size_t validation_seeds = 0);
std::string report_md(const ReportInput& r);

} // namespace rocklab::calibration
