#include "lab/calibration/report.hpp"

#include "io/results.hpp"
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

std::string targets_table(const ReportInput& r) {
  const CalibrationFile& c = *r.file;
  std::string s = "| target | value | tolerance | achieved (mean ± sd over seeds) | error / "
                  "tolerance |\n|---|---|---|---|---|\n";
  for (const Target& t : c.targets) {
    const double m = value_of(r.outcome->measured, t.property);
    s += "| " + t.property + " | " + fmt(t.value) + " | ";
    s += t.absolute ? "± " + fmt(t.tolerance) : fmt(100 * t.tolerance) + " %";
    s +=
        " | " + fmt(m) + " ± " + fmt(value_of(r.sd, t.property)) + " | " + fmt(t.error(m)) + " |\n";
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
  if (sv.per.size() != c.params.size())
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
  // What the packing alone does: the seed-to-seed spread relative to the mean, per unit step.
  s += "| *seed-to-seed sd / mean ÷ 10 %* | |";
  for (const Target& t : c.targets) {
    const double m = value_of(r.outcome->measured, t.property), sd = value_of(r.sd, t.property);
    s.append(" *").append(fmt(std::abs(sd / m) / 0.1, "%.2f")).append("* |");
  }
  return s + "\n\nAn entry smaller than the last row's can be the packing's noise: a different "
             "packing changes the property by that much at the same parameters.\n";
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

std::string convergence_svg(const CalibrationFile& c, const Outcome& out) {
  // |error| in tolerances per target on a log axis, so that a first guess 50 tolerances off and a
  // converged 0.1 both stay legible (a linear axis clipped at 5 drew BTS and direct tension on the
  // same point); a target not measured in a stage (e.g. BTS during the UCS-only stages) has no
  // point there; a hit closer than kFloor is drawn at kFloor.
  constexpr double kFloor = 0.01;
  static const char* const colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                       "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};
  std::vector<PlotSeries> series;
  for (std::size_t k = 0; k < c.targets.size(); ++k) {
    PlotSeries p;
    p.label = c.targets[k].property;
    p.color = colors[k % 8];
    p.dashed = k >= 8;
    for (const Record& r : out.history) {
      const double m = value_of(r.measured, c.targets[k].property);
      if (std::isfinite(m)) {
        p.x.push_back(r.evaluation);
        p.y.push_back(std::max(kFloor, std::abs(c.targets[k].error(m))));
      }
    }
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
  series.push_back(tol);
  return line_plot_svg("Calibration " + c.name + ": error per target", "evaluation",
                       "|error| / tolerance (log scale)", "", series, stages, NAN, true);
}

std::string report_md(const ReportInput& r) {
  const CalibrationFile& c = *r.file;
  const Outcome& out = *r.outcome;
  std::string s = "# Calibration report: " + c.name + "\n\nUnits SI. Calibration file `" + c.file +
                  "`, base card `" + c.material_file + "`; " + std::to_string(c.seeds.size()) +
                  " replicate seed(s) per evaluation.\n\n";
  s += std::string("**") + (out.met ? "Every target met." : "Not every target met.") + "**\n\n";
  s += targets_table(r) + "\n" + params_table(r) + "\n" + sensitivity_table(r);
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
