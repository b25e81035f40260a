// rocklab command-line interface. All quantities in input and output files are SI.
#include "io/output_dir.hpp"
#include "io/scene.hpp"
#include "io/scene_run.hpp"
#include "io/specimen.hpp"
#include "materials/genesis.hpp"

#include <CLI/CLI.hpp>
#include <omp.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <unistd.h>

namespace {

std::atomic<bool> g_interrupt{false};

extern "C" void on_signal(int) {
  g_interrupt.store(true);
}

int run_command(const std::string& scene_file, const std::string& out_dir, bool quiet) {
  rocklab::Scene scene = rocklab::load_scene(scene_file);
  rocklab::RunOptions opts;
  opts.out_dir = out_dir;
  opts.progress = !quiet && ::isatty(STDERR_FILENO);
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

int genesis_command(const std::string& material_file, const std::string& out, bool quiet) {
  const rocklab::MaterialCard card = rocklab::load_material_card(material_file);
  const bool tty = !quiet && ::isatty(STDERR_FILENO);
  rocklab::GenesisResult g = rocklab::run_genesis(
      card,
      [&](const std::string& phase) {
        if (tty)
          std::fprintf(stderr, "[rocklab genesis] %s\n", phase.c_str());
      },
      &g_interrupt);
  if (g_interrupt.load())
    throw std::runtime_error("interrupted; no specimen was written");
  const nlohmann::json report = g.report.to_json();
  nlohmann::json report_in_specimen = report;
  report_in_specimen.erase("seconds"); // the specimen's bytes depend only on the inputs
  const nlohmann::json meta{{"rocklab_version", ROCKLAB_VERSION},
                            {"material_file", material_file},
                            {"material_name", card.name},
                            {"material_hash", card.text_hash},
                            {"seed", card.seed},
                            {"material", card.raw},
                            {"report", report_in_specimen}};
  // The report first (atomically), then the specimen: a specimen never lacks its report.
  const std::string report_file = out + ".report.json";
  rocklab::write_text_file(report_file + ".partial", report.dump(1) + "\n");
  try {
    rocklab::save_model(*g.model, out, meta);
  } catch (...) {
    std::remove((report_file + ".partial").c_str());
    throw;
  }
  std::rename((report_file + ".partial").c_str(), report_file.c_str());
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
    std::printf(
        "bonds        flat joints: %lld bonded, %lld gapped, %lld slit; parallel bonds %lld; "
        "linear %lld; smooth joints %lld\n",
        static_cast<long long>(r.fj_bonded), static_cast<long long>(r.fj_gapped),
        static_cast<long long>(r.fj_slit), static_cast<long long>(r.pb_bonded),
        static_cast<long long>(r.linear), static_cast<long long>(r.smoothjoint));
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

} // namespace

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
  run->add_option("scene", scene_file, "Scene file (JSON)")->required();
  run->add_option("-o,--out", out_dir, "Output directory")->required();
  run->add_option("--threads", threads, "Number of OpenMP threads")->check(CLI::NonNegativeNumber);
  run->add_flag("-q,--quiet", quiet, "No progress line and no summary");

  std::string material_file, specimen_out;
  CLI::App* gen = app.add_subcommand(
      "genesis", "Make a specimen from a material card (docs/material-format.md); writes "
                 "SPECIMEN and SPECIMEN.report.json");
  gen->add_option("material", material_file, "Material card (JSON)")->required();
  gen->add_option("-o,--out", specimen_out, "Specimen file to write")->required();
  gen->add_option("--threads", threads, "Number of OpenMP threads")->check(CLI::NonNegativeNumber);
  gen->add_flag("-q,--quiet", quiet, "No progress and no summary");

  CLI::App* info = app.add_subcommand("info", "Print the version, threads and contact models");

  CLI11_PARSE(app, argc, argv);
  if (threads > 0)
    omp_set_num_threads(threads);
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  try {
    if (*run)
      return run_command(scene_file, out_dir, quiet);
    if (*gen)
      return genesis_command(material_file, specimen_out, quiet);
    if (*info) {
      std::printf("rocklab %s\nthreads %d\ncontact models: linear, linearpbond, flatjoint, "
                  "smoothjoint\nunits: SI\n",
                  ROCKLAB_VERSION, omp_get_max_threads());
      return 0;
    }
  } catch (const rocklab::InputError& e) {
    std::fprintf(stderr, "rocklab: input error: %s\n", e.what());
    return 2;
  } catch (const rocklab::PhysicsError& e) {
    std::fprintf(stderr, "rocklab: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rocklab: error: %s\n", e.what());
    return g_interrupt.load() ? 130 : 1;
  }
  return 0;
}
