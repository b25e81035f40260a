// Lab-test suites: several protocols on one material, run as parallel processes, summarised in
// one table (E, nu, UCS, BTS, direct tension, UCS/BTS, Mohr-Coulomb and Hoek-Brown envelopes).
// Format in docs/protocol-format.md. All quantities SI.
#pragma once

#include <nlohmann/json.hpp>

#include <atomic>
#include <string>
#include <vector>

namespace rocklab {

struct SuiteTest {
  std::string name;         ///< also the test's folder under OUTDIR/tests
  nlohmann::json protocol;  ///< the protocol without its specimen
  nlohmann::json shape;     ///< specimen shape for genesis (null: the card's)
  nlohmann::json cut;       ///< test shape cut from that block (null: the card's)
  std::string specimen_key; ///< tests with the same key share one specimen
};

struct Suite {
  std::string file, name;
  std::string material_file; ///< the material card (absolute or relative to the working dir)
  nlohmann::json material;   ///< the card as read
  std::vector<SuiteTest> tests;
  int parallel = 0; ///< processes at once (0: one per core)
  std::string text_hash;
};

/// Read and validate a suite file; every test's protocol is validated too (errors name the
/// file and the key, e.g. tests[2].loading.confinement).
Suite load_suite(const std::string& path);

/// This program's executable as it was started (/proc/self/exe's target; "" where there is none):
/// the binary a suite or a calibration runs its tests with. Children started from it run this very
/// file even after a rebuild replaced the one at its path (lab/suite_jobs.cpp).
const std::string& own_executable();

struct SuiteOptions {
  std::string out_dir;
  std::string executable; ///< the rocklab binary that runs each test (this process's own)
  int threads = 0;        ///< OpenMP threads per process (0: cores / parallel, at least 1)
  bool progress = false;
  const std::atomic<bool>* interrupt = nullptr;
};

/// A test's specimen shape and cut as given (null: the card's).
struct TestShape {
  std::string name;
  nlohmann::json shape, cut;
};

/// Each distinct specimen's genesis estimate (grains, memory, time on one core), printed as
/// "[rocklab TAG] NAME: genesis estimate: ..." when `print`, before any work starts: a specimen far
/// larger than meant (a width of 12 for 0.012 m) shows itself at once, and one that cannot fit is
/// refused (InputError naming `file` and the test's tests[k].shape).
void say_genesis_estimates(const std::string& card_file, const std::string& file,
                           const std::vector<TestShape>& tests, const char* tag, bool print);

/// Run the suite; writes OUTDIR/summary.json, summary.csv, tests.csv, specimens/, tests/NAME/.
/// Returns the summary. Nothing is left in OUTDIR when it fails or is interrupted.
nlohmann::json run_suite(const Suite& s, const SuiteOptions& o);

/// summary.csv's property columns: the declared headline properties by their place (E, nu, UCS,
/// BTS, direct tension, UCS/BTS, the envelope), then every other one a frame test declares.
std::vector<std::string> summary_columns();
/// tests.csv's columns: name, test, status, every test's declared result columns (table order),
/// then cracks, grains, steps and wall time.
std::vector<std::string> tests_csv_columns();

/// The printed table of a summary (the headline properties, then a line of the others).
std::string summary_table(const nlohmann::json& summary);

} // namespace rocklab
