#include "lab/calibration/campaign.hpp"

#include "io/output_dir.hpp"
#include "lab/calibration/report.hpp"
#include "viz/svg_png.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace fs = std::filesystem;

namespace rocklab::calibration {

namespace {

// One single-seed run per parameter, that parameter moved by +10 % (-10 % at its upper bound;
// by a tenth of its bounds when it is 0), against the same seed at the optimum.
Sensitivity sensitivity(Evaluator& ev, const CalibrationFile& c, const std::vector<double>& x) {
  Sensitivity sv;
  sv.seed = c.seeds.front();
  const Measured base = ev.run(x, Stage::Final, 1).mean;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Param& p = c.params[i].param;
    std::vector<double> y = x;
    y[i] = x[i] != 0 ? x[i] * 1.1 : 0.1 * (p.hi - p.lo);
    if (y[i] > p.hi)
      y[i] = x[i] * 0.9;
    const double rel = x[i] != 0 ? (y[i] - x[i]) / x[i] : 1.0;
    const Measured m = ev.run(y, Stage::Final, 1).mean;
    std::vector<double> row; // NaN where either run did not measure the target
    for (const Target& t : c.targets) {
      const double a = value_of(base, t.property);
      row.push_back((value_of(m, t.property) - a) / a / rel);
    }
    sv.step.push_back(rel);
    sv.per.push_back(row);
  }
  return sv;
}

// One line per evaluation: each measured target and its error in tolerances, the worst, the time.
void print_progress(int n, Stage s, const CalibrationFile& c, const Evaluation& e,
                    std::chrono::steady_clock::duration took) {
  std::string line;
  double worst = 0;
  int unmeasured = 0; // targets whose tests this stage does not run
  for (const Target& t : c.targets)
    if (const double v = value_of(e.mean, t.property); std::isfinite(v)) {
      char b[96];
      std::snprintf(b, sizeof b, " %s %.4g (%+.1f)", t.property.c_str(), v, t.error(v));
      line += b;
      worst = std::max(worst, std::abs(t.error(v)));
    } else {
      ++unmeasured;
    }
  char tail[64] = "", cpu[48] = "";
  if (unmeasured > 0)
    std::snprintf(tail, sizeof tail, " (%d target(s) not measured)", unmeasured);
  if (e.cpu_utilisation >= 0)
    std::snprintf(cpu, sizeof cpu, ", CPU %.0f %% of %d cores", 100 * e.cpu_utilisation, e.cores);
  std::fprintf(stderr,
               "[rocklab calibrate] %d %s:%s; worst %.2f tolerances%s; %zu seed(s), %d cached, "
               "%.0f s%s\n",
               n, stage_name(s), line.c_str(), worst, tail, e.folders.size(), e.cached,
               std::chrono::duration<double>(took).count(), cpu);
}

} // namespace

CampaignSummary run_campaign(const std::string& file, const EvaluatorOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = children_cpu_seconds();
  const CalibrationFile c = load_calibration(file);
  fs::create_directories(o.out_dir);
  // Every evaluation packs each seed's specimens again although only stage 1 changes what
  // packing reads: keep the installed packings beside the evaluations (materials/genesis/
  // packing_cache.cpp; the test processes inherit the setting), unless the user chose a folder.
  if (const char* dir = std::getenv("ROCKLAB_PACKING_CACHE"); !dir || !*dir)
    setenv("ROCKLAB_PACKING_CACHE", fs::absolute(fs::path(o.out_dir) / "packings").c_str(), 1);
  Evaluator ev(c, o);
  std::vector<Param> params;
  for (const CardParam& p : c.params)
    params.push_back(p.param);
  Evaluation last;
  int count = 0;
  const Evaluate evaluate = [&](const std::vector<double>& v, Stage s) {
    const auto t = std::chrono::steady_clock::now();
    last = ev.run(v, s);
    if (o.progress && (!o.ranks || o.ranks->root()))
      print_progress(++count, s, c, last, std::chrono::steady_clock::now() - t);
    return last.mean;
  };
  CampaignSummary cs;
  cs.outcome = calibrate(params, c.targets, evaluate, c.budget);
  if (o.progress && (!o.ranks || o.ranks->root()))
    for (const std::string& n : cs.outcome.notes)
      std::fprintf(stderr, "[rocklab calibrate] note: %s\n", n.c_str());
  ReportInput r;
  r.file = &c;
  r.outcome = &cs.outcome;
  r.sd = last.sd;
  r.final_folders = last.folders;
  std::vector<double> values;
  for (const Param& p : cs.outcome.params)
    values.push_back(p.value);
  if (c.budget.sensitivity) {
    if (o.progress && (!o.ranks || o.ranks->root()))
      std::fprintf(stderr,
                   "[rocklab calibrate] sensitivity: %zu single-seed runs, one per "
                   "parameter\n",
                   values.size());
    r.sensitivity = sensitivity(ev, c, values);
  }
  cs.suites_run = r.suites_run = ev.suites_run();
  cs.suites_cached = r.suites_cached = ev.suites_cached();
  cs.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.wall_seconds = cs.wall_seconds;
  r.cpu_seconds = children_cpu_seconds() - cpu0;
  if (o.ranks)
    r.cpu_seconds = o.ranks->sum(r.cpu_seconds);
  if (o.ranks && !o.ranks->root())
    return cs; // rank 0 writes the outputs
  nlohmann::json card = apply_params(c.material, c.params, values);
  card["source"] = "Calibrated by rocklab calibrate " + fs::path(file).filename().string() +
                   " from " + fs::path(c.material_file).filename().string() + " (" +
                   (cs.outcome.met ? "every target met" : "not every target met") +
                   "; see report.md).";
  const fs::path out(o.out_dir);
  write_text_file(out / "card.json", card.dump(2) + "\n");
  write_text_file(out / "convergence.csv", convergence_csv(c, cs.outcome));
  write_svg_and_png(out / "convergence.svg", convergence_svg(c, cs.outcome));
  write_text_file(out / "report.md", report_md(r));
  return cs;
}

} // namespace rocklab::calibration
