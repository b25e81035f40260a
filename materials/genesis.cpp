// Material genesis: the driver that runs the stages of materials/genesis/ in order, and the
// report. Units SI.
#include "materials/genesis.hpp"

#include "io/progress.hpp"
#include "materials/genesis/stages.hpp"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <sstream>

namespace rocklab {

namespace genesis {

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

double normal(std::mt19937_64& rng, const Distribution& d) {
  if (d.sd <= 0)
    return d.mean;
  // Box-Muller from our own uniform draws (portable, unlike std::normal_distribution).
  const double u1 = std::max(uniform01(rng), 1e-300), u2 = uniform01(rng);
  return std::max(0.0, d.mean + d.sd * std::sqrt(-2 * std::log(u1)) *
                                    std::cos(2 * std::numbers::pi * u2));
}

double grain_volume(int dim, double r) {
  const double pi = std::numbers::pi;
  return dim == 2 ? pi * r * r : 4.0 / 3.0 * pi * r * r * r;
}

double grain_volume_sum(const Model& m) {
  double v = 0;
  for (double r : m.balls.radius)
    v += grain_volume(m.settings.dim, r);
  return v;
}

} // namespace genesis

nlohmann::json GenesisReport::contact_counts() const {
  nlohmann::json c = {
      {"total", contacts}, {"clumps", clumps}, {"linear", linear}, {"smoothjoint", smoothjoint}};
  // Every bonded model's counts, zero where none was made (a report lists the same keys whatever
  // the card's model).
  for_each_model([&]<class M>() {
    if constexpr (BondsCards<M>)
      for (const std::string_view what : M::card_counts) {
        const std::string key = bond_key(M::name, what);
        c[key] = bonded(key);
      }
  });
  return c;
}

nlohmann::json GenesisReport::to_json() const {
  nlohmann::json walls = nlohmann::json::object();
  for (const auto& [name, s] : wall_stress)
    walls[name] = s;
  return {{"units", "SI"},
          {"grains", grains},
          {"floaters", floaters},
          {"escaped_grains_removed", escaped},
          {"specimen", shape_json(shape, dim)},
          {"porosity_target", porosity_target},
          {"porosity_packed", porosity_packed},
          {"porosity_installed", porosity_installed},
          {"porosity", porosity},
          {"packing_friction", packing_friction},
          {"coordination_number", coordination},
          {"contacts", contact_counts()},
          {"installation_pressure_Pa", pressure},
          {"wall_stress_Pa", walls},
          {"residual_mean_stress_Pa", residual_mean_stress},
          {"steps",
           {{"packing", steps_packing},
            {"installation", steps_installation},
            {"release", steps_release}}},
          {"seconds", seconds}};
}

nlohmann::json specimen_meta(const MaterialCard& card, const GenesisReport& report) {
  nlohmann::json r = report.to_json();
  r.erase("seconds");
  return {{"rocklab_version", ROCKLAB_VERSION},
          {"material_file", card.file},
          {"material_name", card.name},
          {"material_hash", card.text_hash},
          {"seed", card.seed},
          {"material", card.raw},
          {"report", r}};
}

namespace {

std::string estimate_line(const genesis::GenesisEstimate& est) {
  if (!(est.grains > 0))
    return "";
  std::ostringstream msg;
  msg << std::setprecision(3) << "estimate: about " << est.grains << " grains, "
      << (est.bytes < 1e9 ? est.bytes / 1e6 : est.bytes / 1e9) << (est.bytes < 1e9 ? " MB" : " GB")
      << ", " << ProgressLine::duration(est.seconds) << " on one core";
  return msg.str();
}

} // namespace

std::string genesis_estimate(MaterialCard card, const GenesisOverrides& o) {
  apply_overrides(card, o);
  return estimate_line(genesis::estimate_genesis(card));
}

GenesisResult run_genesis(const MaterialCard& card,
                          const std::function<void(const std::string&)>& progress,
                          const std::atomic<bool>* interrupt) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  auto out = std::make_unique<Model>();
  Model& m = *out;
  GenesisReport rep;
  m.settings.dim = card.dim;
  m.settings.local_damping = 0.7;
  m.settings.gravity = Vec3::Zero();
  m.settings.slip_events = false; // nobody reads them during genesis
  const std::string estimate = estimate_line(genesis::estimate_genesis(card));
  genesis::Run run(card, m, rep, progress, interrupt);
  if (!estimate.empty())
    run.say(estimate);
  if (card.packing_import.empty()) {
    genesis::place_grains(run);
    const genesis::PackingKey key = genesis::packing_key(run);
    if (!genesis::load_packing(run, key)) {
      genesis::relax_cloud(run);
      genesis::remove_escaped(run);
      genesis::compact(run);
      genesis::remove_escaped(run);
      genesis::store_packing(run, key);
    }
  } else {
    genesis::import_grains(run);
  }
  genesis::remove_floaters(run);
  genesis::join_clumps(run);
  genesis::finalize_contacts(run);
  genesis::release(run);
  genesis::insert_joints(run);
  rep.dim = card.dim;
  rep.grains = static_cast<std::int64_t>(m.balls.size());
  rep.contacts = static_cast<std::int64_t>(m.contacts().size());
  for (const Contact& c : m.contacts()) {
    rep.linear += c.model == model_kind<Linear>;
    rep.smoothjoint += c.model == model_kind<SmoothJoint>;
  }
  rep.seconds = std::chrono::duration<double>(clock::now() - t0).count();
  return {std::move(out), rep};
}

GenesisResult genesis_with_overrides(MaterialCard& card, const GenesisOverrides& o, bool progress,
                                     const std::atomic<bool>* interrupt) {
  apply_overrides(card, o);
  ProgressLine line("genesis", progress);
  GenesisResult g = run_genesis(
      card,
      [&](const std::string& phase) {
        // The estimate is shown at once, on a line of its own: a specimen far larger than meant
        // (a width of 12 for 0.012 m) says so before it runs for minutes without a line.
        const bool estimate = phase.rfind("estimate:", 0) == 0;
        if (estimate || line.due())
          line.show(phase);
        if (estimate)
          line.finish();
      },
      interrupt);
  line.finish();
  return g;
}

} // namespace rocklab
