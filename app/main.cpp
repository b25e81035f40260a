// rocklab command-line interface. All quantities in input and output files are SI.
#include "contact/model_json.hpp"
#include "io/output_dir.hpp"
#include "io/scene.hpp"
#include "io/scene_run.hpp"
#include "io/specimen.hpp"
#include "lab/calibration/campaign.hpp"
#include "lab/protocol_table.hpp"
#include "lab/suite.hpp"
#include "materials/genesis.hpp"

#include <CLI/CLI.hpp>
#include <omp.h>

#include <atomic>
#include <charconv>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>

namespace {

std::atomic<bool> g_interrupt{false};

extern "C" void on_signal(int) {
  g_interrupt.store(true);
}

int run_command(const std::string& scene_file, const std::string& out_dir, bool quiet) {
  rocklab::Scene scene = rocklab::load_scene(scene_file);
  rocklab::RunOptions opts;
  opts.out_dir = out_dir;
  opts.progress = !quiet; // a line in place on a terminal, every ~10 s in a log
  opts.interrupt = &g_interrupt;
  const rocklab::RunSummary s = rocklab::run_scene(scene, opts);
  if (!quiet) {
    const rocklab::Model& m = *scene.model;
    const rocklab::EnergyLedger e = m.energy();
    std::printf("scene        %s%s%s\n", scene_file.c_str(), scene.description.empty() ? "" : " - ",
                scene.description.c_str());
    std::printf("balls        %zu   walls %zu   contacts %zu (%zu carrying load)\n", m.balls.size(),
                m.walls.size(), m.contacts().size(), m.active_contact_count());
    std::printf("steps        %lld   model time %.6g s   last time step %.4g s\n",
                static_cast<long long>(s.steps), s.time, m.timestep());
    std::printf("energy [J]   kinetic %.6g  strain %.6g  slip %.6g  dashpot %.6g  damping %.6g\n",
                e.kinetic(), e.strain, e.slip, e.dashpot, e.local_damping);
    std::printf("             body work %.6g  boundary work %.6g  balance error %.3g\n",
                e.body_work, e.boundary_work, e.balance_error());
    std::printf("events       created %lld  deleted %lld  slip_change %lld  bond_break %lld\n",
                static_cast<long long>(s.events.created), static_cast<long long>(s.events.deleted),
                static_cast<long long>(s.events.slip_change),
                static_cast<long long>(s.events.bond_break));
    std::printf("wall time    %.3f s on %d thread(s)\n", s.wall_seconds, omp_get_max_threads());
    std::printf("wrote        %s/results.json, %s/history.csv\n", out_dir.c_str(), out_dir.c_str());
  }
  return 0;
}

// A shape given on the command line as JSON text (genesis --shape / --cut); null if not given.
rocklab::JsonAt shape_option(const std::string& text, const std::string& option) {
  rocklab::JsonAt at{nullptr, option, option.substr(2)};
  if (text.empty())
    return at;
  // Read as an input file is: the same depth limit, duplicate-key and null checks, and errors
  // that name the option (a 60,000-deep array crashed nlohmann's recursive parser).
  const rocklab::InputText as_file(option, text);
  at.value = rocklab::read_json_file(option);
  return at;
}

int genesis_command(const std::string& material_file, const std::string& out, bool quiet,
                    const std::string& shape, const std::string& cut, std::int64_t seed) {
  rocklab::MaterialCard card = rocklab::load_material_card(material_file);
  rocklab::GenesisOverrides overrides{shape_option(shape, "--shape"), shape_option(cut, "--cut"),
                                      std::nullopt};
  if (seed >= 0)
    overrides.seed = static_cast<std::uint64_t>(seed);
  rocklab::GenesisResult g = rocklab::genesis_with_overrides(card, overrides, !quiet, &g_interrupt);
  if (g_interrupt.load())
    throw std::runtime_error("interrupted; no specimen was written");
  rocklab::save_specimen(*g.model, out, rocklab::specimen_meta(card, g.report), g.report.to_json());
  const std::string report_file = out + ".report.json";
  if (!quiet) {
    const rocklab::GenesisReport& r = g.report;
    std::printf("material     %s (%s, hash %s)\n", card.name.c_str(), material_file.c_str(),
                card.text_hash.c_str());
    std::printf("grains       %lld (floaters %lld)   contacts %lld   coordination %.3f\n",
                static_cast<long long>(r.grains), static_cast<long long>(r.floaters),
                static_cast<long long>(r.contacts), r.coordination);
    std::printf("porosity     target %.4f  locked at %.4f  installed %.4f  specimen %.4f "
                "(packing friction %.3g)\n",
                r.porosity_target, r.porosity_packed, r.porosity_installed, r.porosity,
                r.packing_friction);
    std::printf("bonds       ");
    for (const auto& [what, n] : r.bonds) // the card's bonded model: "flatjoint_slit 9678"
      std::printf(" %s %lld;", what.c_str(), static_cast<long long>(n));
    std::printf(" linear %lld; smooth joints %lld\n", static_cast<long long>(r.linear),
                static_cast<long long>(r.smoothjoint));
    std::printf("stress [Pa]  requested %.4g;", r.pressure);
    for (const auto& [name, s] : r.wall_stress)
      std::printf(" %s %.4g", name.c_str(), s);
    std::printf("\n             residual mean stress after release %.4g\n", r.residual_mean_stress);
    std::printf("steps        packing %lld  installation %lld  release %lld   wall time %.1f s\n",
                static_cast<long long>(r.steps_packing),
                static_cast<long long>(r.steps_installation),
                static_cast<long long>(r.steps_release), r.seconds);
    std::printf("wrote        %s, %s\n", out.c_str(), report_file.c_str());
  }
  return 0;
}

int test_command(const std::string& protocol_file, const std::string& out_dir, bool quiet,
                 std::int64_t checkpoint_every, const std::string& resume) {
  const nlohmann::json j = rocklab::read_json_file(protocol_file);
  const std::unique_ptr<rocklab::LabProtocol> test = rocklab::lab_protocol_of(j, protocol_file);
  rocklab::LabOptions o;
  o.out_dir = out_dir;
  o.progress = !quiet;
  o.interrupt = &g_interrupt;
  o.checkpoint_every = checkpoint_every;
  o.resume_path = resume;
  const rocklab::LabSummary s = test->run(j, protocol_file, o);
  if (s.interrupted) {
    std::fprintf(stderr, "rocklab: interrupted; %s\n",
                 checkpoint_every > 0 ? ("checkpoint written to " + out_dir + ".checkpoint").c_str()
                                      : "nothing was written");
    return 130;
  }
  if (!quiet)
    test->print(s, out_dir);
  // Doubtful or impossible measurements are never silent, even with --quiet.
  std::fflush(stdout);
  if (s.results.contains("warnings"))
    for (const auto& w : s.results["warnings"])
      std::fprintf(stderr, "rocklab: warning: %s\n", w.get<std::string>().c_str());
  return 0;
}

int calibrate_check(const std::string& file) {
  namespace cal = rocklab::calibration;
  const cal::CalibrationFile c = cal::load_calibration(file);
  std::printf("calibration  %s: base card %s, %zu seed(s) per evaluation\n", c.name.c_str(),
              c.material_file.c_str(), c.seeds.size());
  for (const cal::Target& t : c.targets)
    std::printf("target       %-26s %.4g %s %.4g\n", t.property.c_str(), t.value,
                t.absolute ? "+-" : "within (relative)", t.tolerance);
  for (const cal::CardParam& p : c.params)
    std::printf("parameter    %-36s %-15s start %.4g in [%.4g, %.4g]\n", p.key.c_str(),
                cal::role_name(p.param.role), p.param.value, p.param.lo, p.param.hi);
  std::printf("budget       elastic %d, strength %d, ratios %d, polish %d (+1 final); seeds up "
              "to %d where the noise hides a miss; validation on %d-%d fresh seeds from %llu\n",
              c.budget.elastic, c.budget.strength, c.budget.ratios, c.budget.polish,
              c.budget.max_seeds, c.budget.validation_min, c.budget.validation_max,
              static_cast<unsigned long long>(c.budget.validation_first));
  return 0;
}

rocklab::calibration::EvaluatorOptions calibrate_options(const std::string& out_dir, int jobs) {
  rocklab::calibration::EvaluatorOptions o;
  o.out_dir = out_dir;
  o.executable = rocklab::own_executable();
  o.jobs = jobs;
  o.interrupt = &g_interrupt;
  return o;
}

// --check --pilot: the plan, then the start card's tests on the file's seeds and the seeds each
// target needs.
int calibrate_pilot(const std::string& file, const std::string& out_dir, int jobs) {
  calibrate_check(file);
  std::fflush(stdout);
  std::printf("%s",
              rocklab::calibration::run_pilot(file, calibrate_options(out_dir, jobs)).c_str());
  return 0;
}

int calibrate_command(const std::string& file, const std::string& out_dir, bool quiet, int jobs) {
  rocklab::calibration::EvaluatorOptions o = calibrate_options(out_dir, jobs);
  const rocklab::calibration::Ranks ranks; // MPI when started by mpirun
  o.ranks = &ranks;
  o.progress = !quiet;
  if (ranks.size() > 1 && jobs == 0)
    o.jobs = 1; // one test process per rank unless asked: mpirun places the ranks on the cores
  const rocklab::calibration::CampaignSummary cs = rocklab::calibration::run_campaign(file, o);
  const bool validated = cs.validation_seeds == 0 || cs.validation_met;
  if (!quiet && ranks.root()) {
    std::printf("calibration  %s: %zu evaluations (%d suites run, %d cached), %.1f s\n",
                cs.outcome.met ? "every target met" : "NOT every target met",
                cs.outcome.history.size(), cs.suites_run, cs.suites_cached, cs.wall_seconds);
    if (cs.validation_seeds > 0)
      std::printf("validation   %s on %d fresh seeds (report.md)\n",
                  cs.validation_met ? "every target met" : "NOT every target met",
                  cs.validation_seeds);
    std::printf("wrote        %s/card.json, report.md, convergence.csv, convergence.svg\n",
                out_dir.c_str());
  }
  return cs.outcome.met && validated ? 0 : 1;
}

int suite_command(const std::string& suite_file, const std::string& out_dir, bool quiet,
                  int threads) {
  const rocklab::Suite s = rocklab::load_suite(suite_file);
  rocklab::SuiteOptions o;
  o.out_dir = out_dir;
  o.executable = rocklab::own_executable();
  o.threads = threads;
  o.progress = !quiet;
  o.interrupt = &g_interrupt;
  const nlohmann::json sm = rocklab::run_suite(s, o);
  if (!quiet) {
    std::printf("%s", rocklab::summary_table(sm).c_str());
    std::printf("wall time    %.1f s (%d processes x %d threads)\n",
                sm["wall_time_s"].get<double>(), sm["parallel_processes"].get<int>(),
                sm["threads_per_process"].get<int>());
    std::printf("summary      %s/summary.json  %s/summary.csv  %s/tests.csv\n", out_dir.c_str(),
                out_dir.c_str(), out_dir.c_str());
  }
  return sm.value("failed", false) ? 1 : 0;
}

int info_command() {
  std::string models, tests;
  for (const std::string& name : rocklab::model_names()) {
    if (!models.empty())
      models += ", ";
    models += name;
  }
  for (const std::string& name : rocklab::lab_protocol_names()) {
    if (!tests.empty())
      tests += ", ";
    tests += name;
  }
  std::printf("rocklab %s\nthreads %d\ncontact models: %s\nlab tests: %s\nMPI (calibrate): %s\n"
              "units: SI\n",
              ROCKLAB_VERSION, omp_get_max_threads(), models.c_str(), tests.c_str(),
              rocklab::calibration::Ranks::available() ? "yes" : "no");
  return 0;
}

} // namespace

struct CalibrateArgs {
  std::string file, out;
  int jobs = 0;
  bool check = false, pilot = false;
};

int calibrate_dispatch(const CalibrateArgs& a, bool quiet) {
  if (a.pilot)
    return calibrate_pilot(a.file, a.out, a.jobs);
  return a.check ? calibrate_check(a.file) : calibrate_command(a.file, a.out, quiet, a.jobs);
}

CLI::App* add_calibrate(CLI::App& app, CalibrateArgs& a, bool& quiet) {
  CLI::App* c = app.add_subcommand(
      "calibrate", "Fit a material card's micro-parameters to laboratory targets "
                   "(docs/calibration.md); writes OUT/card.json, report.md, convergence.csv/svg "
                   "and keeps every evaluation in OUT/evaluations/ (a rerun reuses them)");
  c->footer("Example: rocklab calibrate lab/calibrate/lac_du_bonnet_2d.json -o out/cal --check");
  c->add_option("calibration", a.file, "Calibration file (JSON)")->required();
  c->add_option("-o,--out", a.out, "Output directory")->required();
  c->add_option("--jobs", a.jobs,
                "Test processes at once (0: one per core; under mpirun: per rank)")
      ->check(CLI::NonNegativeNumber);
  c->add_flag("-q,--quiet", quiet, "No summary");
  CLI::Option* check =
      c->add_flag("--check", a.check, "Check the file and print the plan; run nothing");
  c->add_flag("--pilot", a.pilot,
              "With --check: run the start card's tests on the file's seeds and print the seeds "
              "each target needs for its tolerance (kept in OUT/evaluations/)")
      ->needs(check);
  return c;
}

// Runs a command; input errors exit with 2, physical blow-ups with 3, an interrupt with 130.
// Run a command, turning its exceptions into the documented exit statuses (docs/errors.md); a
// blow-up names the input file it came from (the other errors name their file themselves).
int guarded(const std::string& input, const std::function<int()>& command) {
  try {
    return command();
  } catch (const rocklab::InputError& e) {
    std::fprintf(stderr, "rocklab: input error: %s\n", e.what());
    return 2;
  } catch (const rocklab::PhysicsError& e) {
    std::fprintf(stderr, "rocklab: %s: %s\n", input.c_str(), e.what());
    return 3;
  } catch (const rocklab::OutputError& e) {
    std::fprintf(stderr, "rocklab: output error: %s\n", e.what());
    return 4;
  } catch (const std::filesystem::filesystem_error& e) {
    std::fprintf(stderr, "rocklab: output error: %s\n", e.what());
    return 4;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rocklab: error: %s\n", e.what());
    return g_interrupt.load() ? 130 : 1;
  }
}

// A seed: a whole number in [0, 2^63), checked on the text (a number too large for 64 bits must
// not be clamped silently).
const CLI::Validator kSeed(
    [](std::string& text) -> std::string {
      std::int64_t v = 0;
      const char* end = text.data() + text.size();
      const auto [ptr, ec] = std::from_chars(text.data(), end, v);
      if (ec != std::errc() || ptr != end || v < 0)
        return "Value " + text + " is not a seed: a whole number in [0, 2^63)";
      return {};
    },
    "SEED");

// Parse; -1 to go on, else the exit status: 0 after --help or --version, 2 for a bad command line
// (an input error like any other; CLI11's own codes run from 100 up), with the usage when no
// subcommand was given.
// The options a command takes besides its own: --threads (OpenMP threads) and -q.
void add_run_options(CLI::App* command, int& threads, bool& quiet,
                     const std::string& threads_help = "Number of OpenMP threads") {
  command->add_option("--threads", threads, threads_help)->check(CLI::NonNegativeNumber);
  command->add_flag("-q,--quiet", quiet, "No progress and no summary");
}

int parse_command_line(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    if (argc < 2)
      std::cerr << app.help();
    return 2;
  }
  return -1;
}

int main(int argc, char** argv) {
  CLI::App app{"rocklab - a virtual rock-mechanics laboratory (bonded-particle DEM).\n"
               "All input and output quantities are SI units (m, kg, s, N, Pa, J)."};
  app.set_version_flag("--version", std::string("rocklab ") + ROCKLAB_VERSION);
  app.require_subcommand(1);
  int threads = 0;
  bool quiet = false;
  app.add_option("--threads", threads, "Number of OpenMP threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", quiet, "No progress line and no summary");

  std::string scene_file, out_dir;
  CLI::App* run = app.add_subcommand(
      "run", "Run a hand-built scene (docs/scene-format.md); writes OUT/results.json and "
             "OUT/history.csv");
  run->footer("Example: rocklab run examples/ball_drop.json -o out/ball_drop");
  run->add_option("scene", scene_file, "Scene file (JSON)")->required();
  run->add_option("-o,--out", out_dir, "Output directory")->required();
  add_run_options(run, threads, quiet);

  std::string material_file, specimen_out;
  CLI::App* gen = app.add_subcommand(
      "genesis", "Make a specimen from a material card (docs/material-format.md); writes "
                 "SPECIMEN and SPECIMEN.report.json");
  gen->footer("Example: rocklab genesis materials/granite_fj_2d.json -o out/granite.rlspec");
  gen->add_option("material", material_file, "Material card (JSON)")->required();
  gen->add_option("-o,--out", specimen_out, "Specimen file to write")->required();
  add_run_options(gen, threads, quiet);
  std::string gen_shape, gen_cut;
  std::int64_t gen_seed = -1;
  gen->add_option("--shape", gen_shape,
                  "Replace the card's specimen shape (JSON, e.g. '{\"shape\": \"disk\", "
                  "\"diameter\": 0.05, \"thickness\": 0.025}')");
  gen->add_option("--cut", gen_cut,
                  "Replace the card's cut (a test shape cut from the block, JSON)");
  gen->add_option("--seed", gen_seed, "Replace the card's random seed, [0, 2^63)")->check(kSeed);

  std::string protocol_file, test_out, resume;
  std::int64_t checkpoint_every = 0;
  CLI::App* test = app.add_subcommand(
      "test",
      "Run a laboratory test (docs/protocol-format.md): UCS, triaxial, Brazilian, direct "
      "tension or drop (impact); writes OUT/results.json, history.csv, cracks.csv, vtk/ and plots");
  test->footer("Example: rocklab test lab/ucs_granite.json -o out/ucs");
  test->add_option("protocol", protocol_file, "Protocol file (JSON)")->required();
  test->add_option("-o,--out", test_out, "Output directory")->required();
  test->add_option("--checkpoint-every", checkpoint_every,
                   "Write OUT.checkpoint every N steps (and on Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  test->add_option("--resume", resume, "Continue from a checkpoint of this protocol");
  add_run_options(test, threads, quiet);

  std::string suite_file, suite_out;
  CLI::App* suite = app.add_subcommand(
      "suite", "Run a suite of laboratory tests on one material in parallel processes "
               "(docs/protocol-format.md); writes OUT/summary.json, summary.csv, tests.csv and "
               "OUT/tests/NAME/");
  suite->footer("Example: rocklab suite lab/suites/granite_2d.json -o out/suite");
  suite->add_option("suite", suite_file, "Suite file (JSON)")->required();
  suite->add_option("-o,--out", suite_out, "Output directory")->required();
  add_run_options(suite, threads, quiet, "OpenMP threads per test process");

  CalibrateArgs cal;
  CLI::App* calib = add_calibrate(app, cal, quiet);

  CLI::App* info =
      app.add_subcommand("info", "Print the version, threads, contact models and lab tests");

  if (const int rc = parse_command_line(app, argc, argv); rc >= 0)
    return rc;
  if (threads > 0 && !*suite)
    omp_set_num_threads(threads);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  // Past a file-size limit (ulimit -f) a write fails like on a full disk (exit 4) instead of the
  // signal killing the process with its files half-written.
  std::signal(SIGXFSZ, SIG_IGN);
  const std::string input = *run     ? scene_file
                            : *gen   ? material_file
                            : *suite ? suite_file
                            : *test  ? protocol_file
                            : *calib ? cal.file
                                     : std::string();
  return guarded(input, [&] {
    if (*run)
      return run_command(scene_file, out_dir, quiet);
    if (*gen)
      return genesis_command(material_file, specimen_out, quiet, gen_shape, gen_cut, gen_seed);
    if (*suite)
      return suite_command(suite_file, suite_out, quiet, threads);
    if (*test)
      return test_command(protocol_file, test_out, quiet, checkpoint_every, resume);
    if (*info)
      return info_command();
    if (*calib)
      return calibrate_dispatch(cal, quiet);
    return 0;
  });
}
