#include "lab/calibration/evaluator.hpp"
#include "lab/calibration/noise.hpp"

#include "io/input_error.hpp"
#include "io/json_input.hpp"
#include "io/output_dir.hpp"
#include "io/results.hpp"
#include "lab/property.hpp"
#include "lab/protocol_table.hpp"
#include "lab/suite.hpp"
#include "materials/material_card.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <thread>

#include <sys/resource.h>

namespace fs = std::filesystem;

namespace rocklab::calibration {

double children_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

Evaluator::Evaluator(const CalibrationFile& c, EvaluatorOptions o) : c_(c), o_(std::move(o)) {
  rows_ = SeedRows(!c_.seeds_file.empty() ? c_.seeds_file
                                          : (fs::path(o_.out_dir) / "seeds.csv").string());
}

// Stages 1 and 2 run only the tests that measure what they steer: a test declaring a property
// with a stage role (lab/property.hpp: the UCS test's E, nu and UCS).
nlohmann::json Evaluator::tests_of(Stage s) const {
  if (s == Stage::Ratios || s == Stage::Final)
    return c_.tests;
  nlohmann::json out = nlohmann::json::array();
  for (const auto& t : c_.tests)
    if (std::ranges::any_of(declared_properties(), [&](const DeclaredProperty& d) {
          return d.test == t.value("test", "") && d.p.role != CalibrationRole::Reported;
        }))
      out.push_back(t);
  return out;
}

namespace {
// A seed's tests that were not valid: each declared share of valid tests times what it is a share
// of.
int not_valid_tests(const nlohmann::json& props) {
  int n = 0;
  for (const DeclaredProperty& d : declared_properties())
    if (d.p.share_of)
      n += static_cast<int>(std::lround(json_number(props, d.p.share_of, 0.0) *
                                        (1 - json_number(props, d.p.name, 1.0))));
  return n;
}

// The share of valid tests a property rests on (lab/property.hpp), nullptr where every test counts.
const char* valid_share_of(const std::string& property) {
  const SuiteProperty* d = find_property(property);
  return d ? d->valid_share : nullptr;
}

// A finished replicate is reused unless one of its tests rejected its input (exit status 2). That
// rejection stopped the campaign; once its cause is fixed (in the file, or in rocklab: a 3D packing
// cache that could not be read back) a resumed campaign runs the replicate again instead of
// stopping on the old verdict.
bool reusable(const fs::path& suite_out) {
  const fs::path f = suite_out / "summary.json";
  if (!fs::exists(f))
    return false;
  try {
    const nlohmann::json sm = read_json_file(f.string(), Nulls::Allow);
    for (const auto& t : sm.value("tests", nlohmann::json::array()))
      if (t.value("exit_status", 0) == 2)
        return false;
  } catch (const std::exception&) {
    return false; // unreadable: run it again
  }
  return true;
}
} // namespace

void Evaluator::run_suites(const nlohmann::json& card, const std::vector<const Replicate*>& todo) {
  if (todo.empty())
    return;
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  const int jobs = o_.jobs > 0 ? o_.jobs : cores;
  // Several replicate suites at once, each with its share of the processes and of the cores.
  const int at_once = std::min(static_cast<int>(todo.size()), jobs);
  std::atomic<std::size_t> next{0};
  std::mutex rows_mutex;
  std::vector<std::exception_ptr> errors(todo.size());
  auto worker = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < todo.size();) {
      try {
        const Replicate& r = *todo[i];
        fs::create_directories(r.dir);
        write_text_file(r.dir / "card.json", card.dump(2) + "\n");
        const nlohmann::json suite{{"name", c_.name + "-" + r.dir.filename().string()},
                                   {"units", "SI"},
                                   {"material", "card.json"},
                                   {"parallel", std::max(1, jobs / at_once)},
                                   {"tests", r.tests}};
        write_text_file(r.dir / "suite.json", suite.dump(2) + "\n");
        SuiteOptions so;
        so.out_dir = (r.dir / "suite").string();
        fs::remove_all(so.out_dir); // a rejected earlier attempt's files
        so.executable = o_.executable;
        // Cores left idle (the last seed's suite alone, a suite's last test) are lent to the
        // processes still running (lab/suite_jobs.hpp); several MPI ranks may share a machine,
        // so there each process keeps its fixed share.
        so.threads = o_.ranks && o_.ranks->size() > 1 ? std::max(1, cores / jobs) : 0;
        so.interrupt = o_.interrupt;
        run_suite(load_suite((r.dir / "suite.json").string()), so);
        // Its per-seed row at once: a run killed before the evaluation ends keeps it.
        if ((!o_.ranks || o_.ranks->rank() == 0) && reusable(so.out_dir)) {
          const nlohmann::json sm =
              read_json_file((fs::path(so.out_dir) / "summary.json").string(), Nulls::Allow);
          const std::lock_guard<std::mutex> lock(rows_mutex);
          rows_.add(r.key, r.seed, sm["properties"]);
        }
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < at_once; ++t)
    pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool)
    t.join();
  for (const std::exception_ptr& e : errors)
    if (e)
      std::rethrow_exception(e);
}

// A test that failed leaves its targets unmeasured. One that rejected its input (exit status 2:
// e.g. a Brazilian disk whose vessel cannot reach the card's porosity) fails at every point, so the
// campaign stops naming it; a physical failure at one trial point (blow-up, no peak) is said on
// stderr and the point counts as missing its targets (the optimiser moves away from it).
void Evaluator::check_tests(const nlohmann::json& summary, const fs::path& suite_out,
                            const nlohmann::json& tests) const {
  const std::uint64_t seed = tests.empty() ? 0 : tests[0].value("seed", std::uint64_t{0});
  for (const auto& t : summary.value("tests", nlohmann::json::array())) {
    if (t.value("status", "") == "ok")
      continue;
    std::string error = t.value("error", "");
    while (!error.empty() && error.back() == '\n')
      error.pop_back();
    const std::string what = "test '" + t.value("name", "") + "' of seed " + std::to_string(seed) +
                             " (" + suite_out.string() + ") failed: " + error;
    if (t.value("exit_status", 0) == 2)
      throw InputError(c_.file + ": " + what + " - fix this test in the calibration file");
    if (!o_.ranks || o_.ranks->rank() == 0)
      std::fprintf(stderr, "[rocklab calibrate] warning: %s\n", what.c_str());
  }
}

bool Evaluator::add_seed(int max_seeds) {
  if (static_cast<int>(seeds_.size()) >= max_seeds)
    return false;
  seeds_.push_back(*std::max_element(seeds_.begin(), seeds_.end()) + 1);
  return true;
}

// A finished folder serves, or else a per-seed row (another run's); a folder whose test rejected
// its input is run again whatever a row says (the row is older than that verdict). A stage that
// runs some of the file's tests (elastic, strength: the UCS) is served as well by the replicate
// of all of them at the same card and seed: each test is its own process on its own specimen, so
// its results do not depend on the tests run beside it (after a validation whose seeds join the
// tuned ones, the next stage finds their UCS there instead of running it again).
fs::path Evaluator::cached_source(const Replicate& r, const nlohmann::json*& row) const {
  row = nullptr;
  for (const auto& [dir, key] : {std::pair{r.dir, r.key}, std::pair{r.all_dir, r.all_key}}) {
    if (key.empty())
      continue;
    const bool folder = fs::exists(dir / "suite" / "summary.json");
    if (reusable(dir / "suite"))
      return dir / "suite";
    if (!folder && (row = rows_.find(key)))
      return rows_.path() + " (row " + key + ")";
    if (folder && key == r.key)
      return {}; // its own test rejected its input: run it again
  }
  return {};
}

void Evaluator::adopt_seeds(const std::vector<std::uint64_t>& seeds) {
  for (std::uint64_t s : seeds)
    if (std::find(seeds_.begin(), seeds_.end(), s) == seeds_.end())
      seeds_.push_back(s);
}

namespace {

// The cache key of one replicate: everything its result depends on (the card, the tests with
// their seed, written to `ts`, the version), with the revision of each test's measurement rules
// where it was raised (older keys stay valid for the other tests).
std::string cache_key(const nlohmann::json& card, const nlohmann::json& tests, std::uint64_t seed,
                      nlohmann::json& ts) {
  std::string revisions;
  for (const auto& t : tests)
    if (const auto p = make_lab_protocol(t.value("test", "")); p && p->revision() > 1) {
      revisions += '|';
      revisions += p->name();
      revisions += " r" + std::to_string(p->revision());
    }
  ts = tests;
  for (auto& t : ts)
    t["seed"] = seed;
  return text_hash(card.dump() + "|" + ts.dump() + "|" + ROCKLAB_VERSION + revisions).substr(0, 16);
}

} // namespace

Evaluation Evaluator::run(const std::vector<double>& values, Stage s, std::size_t seeds) {
  const std::vector<std::uint64_t> first(
      seeds_.begin(), seeds_.begin() + static_cast<std::ptrdiff_t>(std::min(seeds, seeds_.size())));
  return run_on(values, s, first);
}

Evaluation Evaluator::run_on(const std::vector<double>& values, Stage s,
                             const std::vector<std::uint64_t>& seeds) {
  const nlohmann::json card = apply_params(c_.material, c_.params, values);
  const nlohmann::json stage_tests = tests_of(s);
  auto key_of = [&](const nlohmann::json& tests, std::uint64_t seed, nlohmann::json& ts) {
    return cache_key(card, tests, seed, ts);
  };
  const fs::path evaluations = fs::path(o_.out_dir) / "evaluations";
  std::vector<Replicate> reps;
  for (std::uint64_t seed : seeds) {
    Replicate r;
    r.seed = seed;
    r.key = key_of(stage_tests, seed, r.tests);
    r.dir = evaluations / r.key;
    if (stage_tests != c_.tests) { // each test runs on its own: the full set's results serve
      nlohmann::json all;
      r.all_key = key_of(c_.tests, seed, all);
      r.all_dir = evaluations / r.all_key;
    }
    reps.push_back(std::move(r));
  }
  // Which replicates are cached is decided once (rank 0) so that every rank shares out the same
  // list; this rank runs every size-th of the missing ones.
  std::string missing;
  for (const Replicate& r : reps) {
    const nlohmann::json* row = nullptr;
    missing += cached_source(r, row).empty() ? '1' : '0';
  }
  const Ranks* ranks = o_.ranks;
  if (ranks)
    missing = ranks->broadcast(missing);
  const int size = ranks ? ranks->size() : 1, rank = ranks ? ranks->rank() : 0;
  std::vector<const Replicate*> mine;
  for (std::size_t i = 0, k = 0; i < reps.size(); ++i)
    if (missing[i] == '1' && static_cast<int>(k++ % size) == rank)
      mine.push_back(&reps[i]);
  std::exception_ptr failed;
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = children_cpu_seconds();
  try {
    run_suites(card, mine);
  } catch (...) {
    failed = std::current_exception();
  }
  if (ranks ? !ranks->all(!failed) : static_cast<bool>(failed)) { // every rank stops together
    if (failed)
      std::rethrow_exception(failed);
    throw std::runtime_error("a suite failed on another MPI rank");
  }
  if (o_.interrupt && o_.interrupt->load())
    throw std::runtime_error("interrupted");
  Evaluation ev;
  ev.cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  if (!mine.empty()) {
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    ev.cpu_utilisation = (children_cpu_seconds() - cpu0) / (std::max(wall, 1e-9) * ev.cores);
  }
  std::map<std::string, std::vector<double>> all;
  for (std::size_t i = 0; i < reps.size(); ++i) {
    (missing[i] == '1' ? run_ : ev.cached) += 1;
    const nlohmann::json* row = nullptr;
    fs::path suite_out = cached_source(reps[i], row);
    if (suite_out.empty()) // it ran and its test rejected its input: check_tests says so
      suite_out = reps[i].dir / "suite";
    ev.folders.push_back(suite_out.string());
    nlohmann::json props;
    if (row) {
      props = *row;
    } else {
      const nlohmann::json sm = read_json_file((suite_out / "summary.json").string(), Nulls::Allow);
      check_tests(sm, suite_out, reps[i].tests);
      props = sm["properties"];
      const bool own = suite_out == reps[i].dir / "suite";
      if ((!ranks || ranks->rank() == 0) && own && !rows_.find(reps[i].key))
        rows_.add(reps[i].key, reps[i].seed, props); // a cached folder's row
    }
    ev.rejected_tests += not_valid_tests(props);
    for (const auto& [k, v] : props.items()) {
      const char* share = valid_share_of(k); // a property resting on a share of 0: left out
      all[k].push_back(v.is_number() && !(share && json_number(props, share, 1.0) == 0)
                           ? v.get<double>()
                           : std::nan(""));
    }
  }
  cached_ += ev.cached;
  for (const std::string& k : average_replicates(all, ev))
    if ((!o_.ranks || o_.ranks->rank() == 0) && !(ev.rejected_tests > 0 && valid_share_of(k)))
      std::fprintf(stderr,
                   "[rocklab calibrate] warning: %s was not measured on every seed; the mean is "
                   "over those that measured it\n",
                   k.c_str());
  return ev;
}

// The mean over the seeds that measured a property: a seed whose test gave none (a Brazilian disk
// that never split) is left out and said, not allowed to blank the whole evaluation (stage 3 would
// see a missing target there and the optimiser a huge penalty).
std::vector<std::string> average_replicates(const std::map<std::string, std::vector<double>>& all,
                                            Evaluation& ev) {
  std::vector<std::string> partial;
  for (const auto& [k, all_v] : all) {
    std::vector<double> v;
    for (double x : all_v)
      if (std::isfinite(x))
        v.push_back(x);
    double m = v.empty() ? std::nan("") : 0.0, q = 0;
    for (double x : v)
      m += x / static_cast<double>(v.size());
    for (double x : v)
      q += (x - m) * (x - m);
    ev.mean[k] = m;
    ev.sd[k] = v.size() > 1 ? std::sqrt(q / static_cast<double>(v.size() - 1)) : 0.0;
    ev.se[k] = standard_error(ev.sd[k], static_cast<int>(v.size()));
    if (!v.empty() && v.size() < all_v.size())
      partial.push_back(k);
  }
  return partial;
}

} // namespace rocklab::calibration
