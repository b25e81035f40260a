#include "lab/calibration/campaign.hpp"

#include "lab/suite.hpp"

#include "io/output_dir.hpp"
#include "lab/calibration/noise.hpp"
#include "lab/calibration/report.hpp"
#include "lab/calibration/rounds.hpp"
#include "lab/property.hpp"
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
void print_progress(const std::string& what, const CalibrationFile& c, const Evaluation& e,
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
  if (e.rejected_tests > 0) {
    line += "; " + std::to_string(e.rejected_tests) + " test(s) not valid left out (" +
            validity_rules() + ")";
  }
  if (e.cpu_utilisation >= 0)
    std::snprintf(cpu, sizeof cpu, ", CPU %.0f %% of %d cores", 100 * e.cpu_utilisation, e.cores);
  std::fprintf(stderr,
               "[rocklab calibrate] %s:%s; worst %.2f tolerances%s; %zu seed(s), %d cached, "
               "%.0f s%s\n",
               what.c_str(), line.c_str(), worst, tail, e.folders.size(), e.cached,
               std::chrono::duration<double>(took).count(), cpu);
}

// The fitted card on fresh seeds it was never tuned on (nor an earlier validation used): as many
// as make each target's standard error half its tolerance (from the last evaluation's scatter),
// within the budget's bounds.
ValidationRun validation(Evaluator& ev, const CalibrationFile& c, const std::vector<double>& values,
                         const Evaluation& last, bool talk) {
  ValidationRun v;
  const int n = validation_seed_count(c.targets, known_scatter(last.sd, last.se),
                                      c.budget.validation_min, c.budget.validation_max);
  v.seeds = fresh_seeds(c.budget.validation_first, n, ev.seeds());
  if (talk)
    std::fprintf(stderr, "[rocklab calibrate] validation: the fitted card on %d fresh seeds\n", n);
  const auto t = std::chrono::steady_clock::now();
  const Evaluation e = ev.run_on(values, Stage::Final, v.seeds);
  if (talk)
    print_progress("validation", c, e, std::chrono::steady_clock::now() - t);
  v.mean = e.mean, v.sd = e.sd, v.se = e.se, v.rejected = e.rejected_tests;
  return v;
}

// The fitted card (its source says the verdict), convergence.csv/.svg and report.md.
void write_outputs(const std::string& file, const CalibrationFile& c, const CampaignSummary& cs,
                   const ReportInput& r, const std::vector<double>& values,
                   const std::string& out_dir) {
  nlohmann::json card = apply_params(c.material, c.params, values);
  std::string verdict = cs.outcome.met ? "every target met" : "not every target met";
  if (cs.validation_seeds > 0)
    verdict += std::string(cs.validation_met ? ", and" : ", not every one") + " on " +
               std::to_string(cs.validation_seeds) + " fresh validation seeds";
  card["source"] = "Calibrated by rocklab calibrate " + fs::path(file).filename().string() +
                   " from " + fs::path(c.material_file).filename().string() + " (" + verdict +
                   "; see report.md).";
  const fs::path out(out_dir);
  write_text_file(out / "card.json", card.dump(2) + "\n");
  write_text_file(out / "convergence.csv", convergence_csv(c, cs.outcome));
  write_svg_and_png(out / "convergence.svg",
                    convergence_svg(c, cs.outcome, &r.validation_mean, r.validation_seeds.size()));
  write_text_file(out / "report.md", report_md(r));
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
  const bool talk = o.progress && (!o.ranks || o.ranks->root());
  std::vector<TestShape> shapes;
  for (const auto& t : c.tests)
    shapes.push_back({t.value("name", std::string()), t.value("shape", nlohmann::json()),
                      t.value("cut", nlohmann::json())});
  say_genesis_estimates(c.material_file, c.file, shapes, "calibrate", talk); // per seed
  const Evaluate evaluate = [&](const std::vector<double>& v, Stage s) {
    const auto t = std::chrono::steady_clock::now();
    last = ev.run(v, s);
    if (talk)
      print_progress(std::to_string(++count) + " " + stage_name(s), c, last,
                     std::chrono::steady_clock::now() - t);
    Measured m = last.mean;
    for (const auto& [k, se] : last.se)
      m[se_key(k)] = se;
    m[kSeedCount] = static_cast<double>(last.folders.size());
    return m;
  };
  const Validate validate = [&](const std::vector<double>& values) {
    return validation(ev, c, values, last, talk);
  };
  const Adopt adopt = [&](const std::vector<std::uint64_t>& s) { ev.adopt_seeds(s); };
  // Where a steered target's miss is within its noise, a seed more (up to the budget's).
  const AddSeed add_seed = [&] {
    const bool added = ev.add_seed(c.budget.max_seeds);
    if (added && talk)
      std::fprintf(stderr, "[rocklab calibrate] a miss within the noise: seed %llu added\n",
                   static_cast<unsigned long long>(ev.seeds().back()));
    return added;
  };
  CampaignSummary cs;
  const Validated val =
      calibrate_and_validate(params, c.targets, evaluate, c.budget, add_seed, validate, adopt);
  cs.outcome = val.outcome;
  if (talk)
    for (const std::string& n : cs.outcome.notes)
      std::fprintf(stderr, "[rocklab calibrate] note: %s\n", n.c_str());
  ReportInput r;
  r.file = &c;
  r.outcome = &cs.outcome;
  r.sd = last.sd;
  r.se = last.se;
  r.rejected = last.rejected_tests;
  r.seeds = static_cast<int>(last.folders.size());
  r.final_folders = last.folders;
  std::vector<double> values;
  for (const Param& p : cs.outcome.params)
    values.push_back(p.value);
  if (val.rounds > 0) {
    r.validation_seeds = val.validation.seeds;
    r.validation_rejected = val.validation.rejected;
    r.validation_mean = val.validation.mean;
    r.validation_sd = val.validation.sd;
    r.validation_se = val.validation.se;
    r.validation_rounds = val.rounds;
    cs.validation_seeds = static_cast<int>(r.validation_seeds.size());
    cs.validation_met = val.met;
  }
  if (c.budget.sensitivity) {
    if (talk)
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
  write_outputs(file, c, cs, r, values, o.out_dir);
  return cs;
}

std::string run_pilot(const std::string& file, const EvaluatorOptions& o) {
  const CalibrationFile c = load_calibration(file);
  fs::create_directories(o.out_dir);
  Evaluator ev(c, o);
  std::vector<double> start;
  for (const CardParam& p : c.params)
    start.push_back(p.param.value);
  // The pilot is one evaluation of every test on every seed: say so before the wait.
  std::fprintf(stderr,
               "[rocklab calibrate] pilot: the start card's %zu test(s) on %zu seed(s), in "
               "%s/evaluations/ (as long as that many suites)\n",
               c.tests.size(), c.seeds.size(), o.out_dir.c_str());
  const Evaluation e = ev.run(start, Stage::Final);
  std::string s;
  char b[256];
  std::snprintf(b, sizeof b, "pilot        the start card on %zu seed(s), every test\n",
                e.folders.size());
  s += b;
  if (e.rejected_tests > 0) {
    s += "pilot        " + std::to_string(e.rejected_tests) +
         " test(s) not valid left out of the means that rest on them (" + validity_rules() + ")\n";
  }
  const Measured scatter = known_scatter(e.sd, e.se);
  for (const Target& t : c.targets) {
    const double sd = value_of(e.sd, t.property);
    const int need = seeds_needed(t, value_of(scatter, t.property));
    std::snprintf(b, sizeof b, "seeds        %-26s mean %.4g, sd %.3g, standard error %.3g; %s\n",
                  t.property.c_str(), value_of(e.mean, t.property), sd, value_of(e.se, t.property),
                  need < 0 ? "one seed cannot tell its scatter: give 2 or more"
                           : ("needs " + std::to_string(need) +
                              " seed(s) for a standard error of half its tolerance")
                                 .c_str());
    s += b;
  }
  return s;
}

} // namespace rocklab::calibration
