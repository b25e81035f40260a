// `rocklab calibrate FILE -o OUTDIR`: the stages over real evaluations, and what the user reads
// afterwards (the fitted card, report.md, convergence.csv). Units SI.
#pragma once

#include "lab/calibration/evaluator.hpp"

#include <string>

namespace rocklab::calibration {

struct CampaignSummary {
  Outcome outcome;
  int validation_seeds = 0;    ///< fresh seeds the fitted card was run on (0: none)
  bool validation_met = false; ///< every target met on them
  int suites_run = 0, suites_cached = 0;
  double wall_seconds = 0;
};

/// Runs the calibration of `file`; OUTDIR/evaluations/ keeps every evaluation (the cache), and
/// OUTDIR/card.json, report.md, convergence.csv are written at the end.
CampaignSummary run_campaign(const std::string& file, const EvaluatorOptions& o);

/// A pilot run for `rocklab calibrate --check --pilot`: the start card's tests (every test of the
/// file) on the file's seeds, kept in OUTDIR/evaluations/ like any evaluation, and a table of
/// each target's mean, seed-to-seed sd, standard error and the seeds it needs for that error to
/// be half its tolerance.
std::string run_pilot(const std::string& file, const EvaluatorOptions& o);

} // namespace rocklab::calibration
