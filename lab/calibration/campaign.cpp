#include "lab/calibration/campaign.hpp"

#include "io/output_dir.hpp"
#include "io/results.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace rocklab::calibration {

namespace {

std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

double worst_error(const std::vector<Target>& targets, const Measured& m) {
  double w = 0;
  for (const Target& t : targets) {
    const auto it = m.find(t.property);
    w = std::max(w, std::abs(t.error(it == m.end() ? std::nan("") : it->second)));
  }
  return w;
}

std::string convergence_csv(const CalibrationFile& c, const Outcome& out) {
  std::string s = "evaluation,stage";
  for (const CardParam& p : c.params)
    s += "," + p.key;
  for (const Target& t : c.targets)
    s += "," + t.property;
  s += ",worst_error_in_tolerances\n";
  for (const Record& r : out.history) {
    s += std::to_string(r.evaluation) + "," + stage_name(r.stage);
    for (double v : r.values)
      s += "," + format_double(v);
    for (const Target& t : c.targets) {
      const auto it = r.measured.find(t.property);
      s += "," + (it == r.measured.end() ? std::string() : format_double(it->second));
    }
    s += "," + format_double(worst_error(c.targets, r.measured)) + "\n";
  }
  return s;
}

std::string report_md(const CalibrationFile& c, const CampaignSummary& cs, const Measured& sd) {
  const Outcome& out = cs.outcome;
  std::string s = "# Calibration report: " + c.name + "\n\nUnits SI. Calibration file `" + c.file +
                  "`, base card `" + c.material_file + "`; " + std::to_string(c.seeds.size()) +
                  " replicate seed(s) per evaluation; " + std::to_string(out.history.size()) +
                  " evaluations (" + std::to_string(cs.suites_run) + " suites run, " +
                  std::to_string(cs.suites_cached) + " from the cache), " + fmt(cs.wall_seconds) +
                  " s wall time.\n\n";
  s += std::string("**") + (out.met ? "Every target met." : "Not every target met.") + "**\n\n";
  s += "| target | value | tolerance | achieved (mean ± sd over seeds) | error / tolerance |\n";
  s += "|---|---|---|---|---|\n";
  for (const Target& t : c.targets) {
    const auto it = out.measured.find(t.property);
    const double m = it == out.measured.end() ? std::nan("") : it->second;
    const auto is = sd.find(t.property);
    s += "| " + t.property + " | " + fmt(t.value) + " | " +
         (t.absolute ? "± " + fmt(t.tolerance) : fmt(100 * t.tolerance) + " %") + " | " + fmt(m) +
         " ± " + fmt(is == sd.end() ? std::nan("") : is->second) + " | " + fmt(t.error(m)) + " |\n";
  }
  s += "\n| parameter | role | start | final | bounds |\n|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < c.params.size(); ++i) {
    const Param& p = c.params[i].param;
    s += "| " + p.name + " | " + role_name(p.role) + " | " + fmt(p.value) + " | " +
         fmt(out.params[i].value) + " | [" + fmt(p.lo) + ", " + fmt(p.hi) + "] |\n";
  }
  s += "\nconvergence.csv has every evaluation (stage, parameters, measured targets, worst "
       "error).\n";
  return s;
}

} // namespace

CampaignSummary run_campaign(const std::string& file, const EvaluatorOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const CalibrationFile c = load_calibration(file);
  fs::create_directories(o.out_dir);
  Evaluator ev(c, o);
  std::vector<Param> params;
  for (const CardParam& p : c.params)
    params.push_back(p.param);
  Measured last_sd;
  const Evaluate evaluate = [&](const std::vector<double>& v, Stage s) {
    const Evaluation e = ev.run(v, s);
    last_sd = e.sd;
    return e.mean;
  };
  CampaignSummary cs;
  cs.outcome = calibrate(params, c.targets, evaluate, c.budget);
  cs.suites_run = ev.suites_run();
  cs.suites_cached = ev.suites_cached();
  cs.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<double> values;
  for (const Param& p : cs.outcome.params)
    values.push_back(p.value);
  nlohmann::json card = apply_params(c.material, c.params, values);
  card["source"] = "Calibrated by rocklab calibrate " + fs::path(file).filename().string() +
                   " from " + fs::path(c.material_file).filename().string() + " (" +
                   (cs.outcome.met ? "every target met" : "not every target met") +
                   "; see report.md).";
  if (o.ranks && !o.ranks->root())
    return cs; // rank 0 writes the outputs
  const fs::path out(o.out_dir);
  write_text_file(out / "card.json", card.dump(2) + "\n");
  write_text_file(out / "convergence.csv", convergence_csv(c, cs.outcome));
  write_text_file(out / "report.md", report_md(c, cs, last_sd));
  return cs;
}

} // namespace rocklab::calibration
