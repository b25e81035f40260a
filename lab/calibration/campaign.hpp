// `rocklab calibrate FILE -o OUTDIR`: the stages over real evaluations, and what the user reads
// afterwards (the fitted card, report.md, convergence.csv). Units SI.
#pragma once

#include "lab/calibration/evaluator.hpp"

#include <string>

namespace rocklab::calibration {

struct CampaignSummary {
  Outcome outcome;
  int suites_run = 0, suites_cached = 0;
  double wall_seconds = 0;
};

/// Runs the calibration of `file`; OUTDIR/evaluations/ keeps every evaluation (the cache), and
/// OUTDIR/card.json, report.md, convergence.csv are written at the end.
CampaignSummary run_campaign(const std::string& file, const EvaluatorOptions& o);

} // namespace rocklab::calibration
