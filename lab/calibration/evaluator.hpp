// One calibration evaluation: the card for a parameter vector, a suite of the tests a stage needs
// on every replicate seed, the mean of their properties. Each (card, tests, seed, rocklab version)
// is cached on disk by its hash, so a killed campaign resumes and reuses what it had. Units SI.
#pragma once

#include "lab/calibration/calibration_file.hpp"
#include "lab/calibration/ranks.hpp"
#include "lab/calibration/seed_rows.hpp"

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

namespace rocklab::calibration {

struct EvaluatorOptions {
  std::string out_dir;    ///< evaluations go to OUT_DIR/evaluations/HASH/
  std::string executable; ///< the rocklab binary that runs each test
  int jobs = 0;           ///< test processes at once on this rank (0: one per core)
  const std::atomic<bool>* interrupt = nullptr;
  const Ranks* ranks = nullptr; ///< MPI ranks sharing the suites (nullptr: this process only)
  bool progress = false;        ///< one line per evaluation on stderr (rank 0)
};

/// Properties of one evaluation: the mean over the seeds, the sample standard deviation (0 for
/// one seed) and the standard error of the mean (NaN for one seed), by property name.
struct Evaluation {
  Measured mean, sd, se;
  std::vector<std::string> folders; ///< the suites' output folders, one per seed
  /// Tests not valid by their own rule (lab/property.hpp, validity_rules(): a Brazilian disk
  /// fractured at a platen): the properties resting on them leave those seeds out of their means.
  int rejected_tests = 0;
  int cached = 0; ///< seeds found in the cache
  /// CPU time of the test processes this rank ran for it over (wall time x cores), [0, 1];
  /// -1 when every seed came from the cache.
  double cpu_utilisation = -1;
  int cores = 1; ///< the cores of this rank's machine
};

/// CPU seconds of the finished child processes (the tests) of this process.
double children_cpu_seconds();

/// Adds to `ev` the mean, sample standard deviation and standard error of each property
/// over the seeds that measured it (non-finite values are left out; NaN when none did); returns
/// the properties some seeds did not measure.
std::vector<std::string> average_replicates(const std::map<std::string, std::vector<double>>& all,
                                            Evaluation& ev);

class Evaluator {
public:
  /// Per-seed rows come from and go to the file's seeds_file, else OUT_DIR/seeds.csv.
  Evaluator(const CalibrationFile& c, EvaluatorOptions o);
  /// The tests of a stage: Elastic and Strength run the UCS tests only, Ratios and Final all.
  nlohmann::json tests_of(Stage s) const;
  /// Runs (or finds in the cache) the tests of stage `s` on the first `seeds` replicate seeds.
  Evaluation run(const std::vector<double>& values, Stage s, std::size_t seeds = SIZE_MAX);
  /// The same on the given seeds (the validation's fresh seeds).
  Evaluation run_on(const std::vector<double>& values, Stage s,
                    const std::vector<std::uint64_t>& seeds);
  /// The replicate seeds of every evaluation from now on: the file's, and those added.
  const std::vector<std::uint64_t>& seeds() const { return seeds_; }
  /// One more replicate seed (the next integer after the largest used), while fewer than
  /// `max_seeds`; false when there are that many already.
  bool add_seed(int max_seeds);
  /// These seeds become replicate seeds too (a failed validation's: its results are evidence).
  void adopt_seeds(const std::vector<std::uint64_t>& seeds);
  int suites_run() const { return run_; }
  /// The per-seed results merged and written (its path for the report).
  const SeedRows& seed_rows() const { return rows_; }
  int suites_cached() const { return cached_; }

private:
  /// One replicate: its cache folder and suite (tests with this seed).
  struct Replicate {
    std::filesystem::path dir;
    nlohmann::json tests;
    std::string key; ///< the cache key (the per-seed row's key)
    std::uint64_t seed = 0;
    /// For a stage that runs some of the file's tests: the replicate of all of them (same card
    /// and seed), whose results serve it too (empty: the stage runs all of them).
    std::filesystem::path all_dir;
    std::string all_key;
  };
  /// Where a replicate's properties are without running it: "" (run it), else the summary.json
  /// folder or, with `row` set, a per-seed row.
  std::filesystem::path cached_source(const Replicate& r, const nlohmann::json*& row) const;
  /// Runs the suites of these replicates, up to `jobs` test processes at once in all.
  void run_suites(const nlohmann::json& card, const std::vector<const Replicate*>& todo);
  void check_tests(const nlohmann::json& summary, const std::filesystem::path& suite_out,
                   const nlohmann::json& tests) const;

  const CalibrationFile& c_;
  EvaluatorOptions o_;
  std::vector<std::uint64_t> seeds_ = c_.seeds;
  SeedRows rows_;
  int run_ = 0, cached_ = 0;
};

} // namespace rocklab::calibration
