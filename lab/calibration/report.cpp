#include "lab/calibration/report.hpp"

#include "io/results.hpp"
#include "lab/calibration/noise.hpp"
#include "lab/property.hpp"
#include "viz/svg_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace rocklab::calibration {

namespace {

std::string fmt(double v, const char* f = "%.4g") {
  char b[32];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

// A measured mean's cell, `text`, or "not measured" where no seed measured it.
std::string measured_cell(double m, const std::string& text) {
  return std::isfinite(m) ? text : "not measured";
}

// A mean with its standard error; a mean over one value (a single valid Brazilian disk) has none.
std::string mean_se(double m, double se) {
  return measured_cell(
      m, fmt(m) + (std::isfinite(se) ? " ± " + fmt(se) : " (one value: no standard error)"));
}

// A target's error in tolerances, "–" where nothing measured it.
std::string error_cell(const Target& t, double m, const char* f) {
  return std::isfinite(m) ? fmt(t.error(m), f) : "–";
}

// The sensitivity table ran for this file's free parameters (one row per parameter); the
// parameter-uncertainty table is built from it.
bool has_sensitivity(const ReportInput& r) {
  return !r.file->params.empty() && r.sensitivity.per.size() == r.file->params.size();
}

// A target's tolerance as the tables give it: "5 %" (relative) or "± 0.03" (absolute).
std::string tolerance_cell(const Target& t) {
  return t.absolute ? "± " + fmt(t.tolerance) : fmt(100 * t.tolerance) + " %";
}

std::string targets_table(const ReportInput& r) {
  const CalibrationFile& c = *r.file;
  std::string s = "| target | value | tolerance | achieved (mean ± sd over seeds) | error / "
                  "tolerance |\n|---|---|---|---|---|\n";
  for (const Target& t : c.targets) {
    const double m = value_of(r.outcome->measured, t.property);
    s += "| " + t.property + " | " + fmt(t.value) + " | ";
    s += tolerance_cell(t);
    s += " | " + measured_cell(m, fmt(m) + " ± " + fmt(value_of(r.sd, t.property))) + " | " +
         error_cell(t, m, "%.4g") + " |\n";
  }
  return s;
}

std::string params_table(const ReportInput& r) {
  const CalibrationFile& c = *r.file;
  std::string s = "| parameter | role | start | final | bounds |\n|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    const Param& p = c.params[i].param;
    s += "| " + p.name + " | " + role_name(p.role) + " | " + fmt(p.value) + " | " +
         fmt(r.outcome->params[i].value) + " | [" + fmt(p.lo) + ", " + fmt(p.hi) + "] |\n";
  }
  return s;
}

std::string sensitivity_table(const ReportInput& r) {
  const CalibrationFile& c = *r.file;
  const Sensitivity& sv = r.sensitivity;
  if (!has_sensitivity(r))
    return "No sensitivity table (`\"budget\": {\"sensitivity\": false}`, or the campaign "
           "stopped before it).\n";
  std::string s = "Sensitivity at the optimum: d ln(property) / d ln(parameter), from one run per "
                  "parameter with that parameter moved by the step shown, on seed " +
                  std::to_string(sv.seed) +
                  " (the same packing as the reference run). 1 means the property moves in "
                  "proportion.\n\n| parameter | "
                  "step |";
  std::string rule = "|---|---|";
  for (const Target& t : c.targets) {
    s += " " + t.property + " |";
    rule += "---|";
  }
  s += "\n" + rule + "\n";
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    s.append("| ").append(c.params[i].key).append(" | ");
    s.append(fmt(100 * sv.step[i], "%+.0f")).append(" % |");
    for (double d : sv.per[i])
      s.append(" ").append(fmt(d, "%.2f")).append(" |");
    s += "\n";
  }
  // What the packing alone does: the seed-to-seed spread relative to the mean, per unit step
  // (over the validation seeds where there are any: one tuned seed has no spread).
  const bool val = !r.validation_seeds.empty();
  s += "| *seed-to-seed sd / mean ÷ 10 %* | |";
  for (const Target& t : c.targets) {
    const double m = value_of(val ? r.validation_mean : r.outcome->measured, t.property),
                 sd = value_of(val ? r.validation_sd : r.sd, t.property);
    const double spread = std::abs(sd / m) / 0.1;
    s.append(std::isfinite(spread) ? " *" + fmt(spread, "%.2f") + "* |" : " – |");
  }
  return s + "\n\nAn entry smaller than the last row's can be the packing's noise: a different "
             "packing changes the property by that much at the same parameters.\n";
}

// Every target met and confirmed on the validation seeds.
bool validation_confirmed(const ReportInput& r) {
  Measured m = r.validation_mean;
  for (const auto& [k, se] : r.validation_se)
    m[se_key(k)] = se;
  return every_target_confirmed(r.file->targets, m);
}

// Each target on the tuned seeds and on the fresh validation seeds, with its standard error.
std::string validation_table(const ReportInput& r) {
  const CalibrationFile& c = *r.file;
  const std::size_t nv = r.validation_seeds.size();
  if (nv == 0)
    return "No validation on fresh seeds (`\"budget\": {\"validation_max\": 0}`).\n";
  std::string seeds;
  for (std::size_t i = 0; i < nv; ++i)
    seeds += (i ? ", " : "") + std::to_string(r.validation_seeds[i]);
  std::string s = "The fitted card on " + std::to_string(nv) +
                  " fresh seeds it was never tuned on (" + seeds +
                  "): each mean ± its standard error (sd / √seeds). A target is *met* when the "
                  "validation mean is within its tolerance and its standard error is at most half "
                  "the tolerance; where the standard error exceeds that, the last column gives the "
                  "seeds it needs." +
                  (r.validation_rounds > 1
                       ? " This is validation " + std::to_string(r.validation_rounds) +
                             ": the earlier ones failed and their seeds joined the tuned ones "
                             "(notes below)."
                       : std::string()) +
                  "\n\n"
                  "| target | value | tolerance | tuned (" +
                  std::to_string(r.seeds) + (r.seeds == 1 ? " seed" : " seeds") +
                  ") | validation (" + std::to_string(nv) +
                  " seeds) | error / tolerance | met | seeds for SE ≤ ½ tolerance |\n"
                  "|---|---|---|---|---|---|---|---|\n";
  for (const Target& t : c.targets) {
    const double m = value_of(r.validation_mean, t.property);
    const double se = value_of(r.validation_se, t.property);
    const int need = seeds_needed(t, value_of(r.validation_sd, t.property));
    s += "| " + t.property + " | " + fmt(t.value) + " | " + tolerance_cell(t) + " | " +
         mean_se(value_of(r.outcome->measured, t.property), value_of(r.se, t.property)) + " | " +
         mean_se(m, se) + " | " + error_cell(t, m, "%+.2f") + " | " +
         (target_confirmed(t, m, se)  ? "yes"
          : std::abs(t.error(m)) <= 1 ? "**not confirmed** (standard error above ½ tolerance)"
                                      : "**no**") +
         " | ";
    // A target no validation seed measured (every Brazilian disk not valid) has no scatter to
    // count seeds from: more seeds of the same disk would not measure it, another loading of the
    // disk or a finer one (more grains across) might.
    s += !std::isfinite(m) ? "– (no seed measured it: more seeds of this test would not; it needs "
                             "a loading or a resolution whose disks split at the centre)"
         : need < 0
             ? "?"
             : std::to_string(need) + (se > 0.5 * tolerance_in_units(t) ? " (more than run)" : "");
    s += " |\n";
  }
  if (r.rejected + r.validation_rejected > 0)
    s += "\nTests left out of the means that rest on them (not valid: " + validity_rules() +
         "): " + std::to_string(r.rejected) + " of " + std::to_string(r.seeds) + " tuned, " +
         std::to_string(r.validation_rejected) + " of " + std::to_string(nv) +
         " validation seeds.\n";
  return s;
}

// What the seed noise leaves of each fitted parameter (noise.hpp): from the sensitivity table and
// the tuned means' relative standard errors (the seed sd measured on the validation seeds when
// there are any: more seeds, a better estimate).
std::string uncertainty_table(const ReportInput& r) {
  const CalibrationFile& c = *r.file;
  if (!has_sensitivity(r))
    return "No parameter uncertainty (it needs the sensitivity table).\n";
  const bool val = !r.validation_seeds.empty();
  std::vector<double> rel;
  for (const Target& t : c.targets) {
    const double sd = value_of(val ? r.validation_sd : r.sd, t.property);
    const double m = value_of(val ? r.validation_mean : r.outcome->measured, t.property);
    rel.push_back(sd / std::sqrt(std::max(r.seeds, 1)) / std::abs(m));
  }
  const std::vector<ParamUncertainty> u = parameter_uncertainty(r.sensitivity.per, rel);
  std::string s =
      "What the packings' noise leaves of the fitted parameters: the linearised least-squares "
      "uncertainty from the sensitivity table and each target's relative standard error over "
      "the " +
      std::to_string(r.seeds) + " tuned seed(s) (the seed-to-seed sd " +
      (val ? "of the validation seeds" : "of the tuned seeds") +
      "). *Not identifiable*: the targets given cannot pin it — it can trade with other "
      "parameters, or move by more than ±50 % (1 sd), without a target changing by more than its "
      "noise; fix it from other data or add a target it moves.\n\n| parameter | final | ± 1 sd "
      "| identifiable |\n|---|---|---|---|\n";
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    s += "| " + c.params[i].key + " | " + fmt(r.outcome->params[i].value) + " | ";
    s += std::isfinite(u[i].sd_ln) ? fmt(100 * std::expm1(u[i].sd_ln), "%.1f") + " %" : "—";
    s += u[i].identifiable ? " | yes |\n"
         : u[i].blind_share >= 0.1
             ? " | **no**: " + fmt(100 * u[i].blind_share, "%.0f") +
                   " % of it lies where no target sees it (inert, or trading with other "
                   "parameters) |\n"
             : std::string(" | **no**: the noise leaves it uncertain by more than 50 % |\n");
  }
  return s;
}

} // namespace

double worst_error(const std::vector<Target>& targets, const Measured& m) {
  double w = 0;
  for (const Target& t : targets) {
    const double v = value_of(m, t.property);
    if (m.count(t.property))
      w = std::max(w, std::isfinite(v) ? std::abs(t.error(v)) : INFINITY);
  }
  return w;
}

std::string convergence_csv(const CalibrationFile& c, const Outcome& out) {
  std::string s = "evaluation,stage";
  for (const CardParam& p : c.params)
    s.append(",").append(p.key);
  for (const Target& t : c.targets)
    s.append(",").append(t.property);
  s += ",worst_error_in_tolerances\n";
  for (const Record& r : out.history) {
    s.append(std::to_string(r.evaluation)).append(",").append(stage_name(r.stage));
    for (double v : r.values)
      s.append(",").append(format_double(v));
    for (const Target& t : c.targets)
      s.append(",").append(r.measured.count(t.property)
                               ? format_double(value_of(r.measured, t.property))
                               : std::string());
    s.append(",").append(format_double(worst_error(c.targets, r.measured))).append("\n");
  }
  return s;
}

std::string convergence_svg(const CalibrationFile& c, const Outcome& out,
                            const Measured* validation, std::size_t validation_seeds) {
  // |error| in tolerances per target on a log axis, so that a first guess 50 tolerances off and a
  // converged 0.1 both stay legible (a linear axis clipped at 5 drew BTS and direct tension on the
  // same point); a target not measured in a stage (e.g. BTS during the UCS-only stages) has no
  // point there; a hit closer than kFloor is drawn at kFloor.
  constexpr double kFloor = 0.01;
  static const char* const colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                       "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};
  const int last = out.history.empty() ? 0 : out.history.back().evaluation;
  const bool val = validation && validation_seeds > 0;
  std::vector<PlotSeries> series;
  for (std::size_t k = 0; k < c.targets.size(); ++k) {
    PlotSeries p;
    p.label = c.targets[k].property;
    p.color = colors[k % 8];
    p.dashed = k >= 8;
    auto add = [&](int x, const Measured& measured) {
      const double m = value_of(measured, c.targets[k].property);
      if (std::isfinite(m)) {
        p.x.push_back(x);
        p.y.push_back(std::max(kFloor, std::abs(c.targets[k].error(m))));
      }
    };
    for (const Record& r : out.history)
      add(r.evaluation, r.measured);
    if (val)
      add(last + 1, *validation);
    if (p.x.empty())
      p.label += " (not measured)";
    series.push_back(p);
  }
  PlotSeries tol{"tolerance (1)", {}, {}, "#000000", true};
  std::vector<PlotMarker> stages;
  for (const Record& r : out.history) {
    tol.x.push_back(r.evaluation);
    tol.y.push_back(1);
    if (stages.empty() || stages.back().label != stage_name(r.stage))
      stages.push_back({static_cast<double>(r.evaluation), 0, stage_name(r.stage)});
  }
  if (val) {
    tol.x.push_back(last + 1);
    tol.y.push_back(1);
    stages.push_back({static_cast<double>(last + 1), 0,
                      "fresh seeds (" + std::to_string(validation_seeds) + ")"});
  }
  series.push_back(tol);
  return line_plot_svg("Calibration " + c.name + ": error per target", "evaluation",
                       "|error| / tolerance (log scale)", "", series, stages, NAN, true, true);
}

std::string report_md(const ReportInput& r) {
  const CalibrationFile& c = *r.file;
  const Outcome& out = *r.outcome;
  std::string s = "# Calibration report: " + c.name + "\n\nUnits SI. Calibration file `" + c.file +
                  "`, base card `" + c.material_file + "`; " + std::to_string(r.seeds) +
                  " replicate seed(s) in the final evaluation.\n\n";
  s += std::string("**") + (out.met ? "Every target met" : "Not every target met") +
       " on the tuned seeds";
  if (!r.validation_seeds.empty())
    s += validation_confirmed(r) ? "; every target met on the fresh validation seeds."
                                 : "; not every target met on the fresh validation seeds.";
  s += "**\n\n";
  s += targets_table(r) + "\n## Validation on fresh seeds\n\n" + validation_table(r) + "\n" +
       params_table(r) + "\n" + sensitivity_table(r) + "\n## Parameter uncertainty\n\n" +
       uncertainty_table(r);
  if (!out.notes.empty()) {
    s += "\n**Noticed on the way:**\n\n";
    for (const std::string& n : out.notes)
      s += "- " + n + "\n";
  }
  s += "\n**Cost:** " + std::to_string(out.history.size()) + " evaluations; " +
       std::to_string(r.suites_run) + " suites run, " + std::to_string(r.suites_cached) +
       " from the cache; " + fmt(r.wall_seconds, "%.0f") + " s wall time, " +
       fmt(r.cpu_seconds, "%.0f") + " s CPU time of the test processes.\n\n";
  s += "convergence.csv has every evaluation (stage, parameters, measured targets, worst error); "
       "convergence.svg draws each target's error against the evaluation; card.json is the "
       "fitted card. The final evaluation's suites (summary.json, each test's results):\n\n";
  for (const std::string& f : r.final_folders)
    s += "- `" + f + "`\n";
  return s;
}

} // namespace rocklab::calibration
