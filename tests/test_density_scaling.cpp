// Density scaling (Model::scale_density): it raises the time step to the chosen quantile of the
// grains' own stable steps, keeps the energy ledger closed and each grain's kinetic energy, and
// changes the dynamics only: a loaded packing comes to the same equilibrium.
#include "helpers.hpp"

#include "io/specimen.hpp"

#include <array>
#include <random>

using namespace rocklab;
using rocklab::test::near_rel;

namespace {

constexpr int kSide = 5;    // balls per lattice edge
constexpr double kA = 2e-3; // lattice spacing [m]

/// A bonded cube of kSide^3 balls on a simple cubic lattice with radii drawn from [0.75, 1.0] mm
/// (parallel bonds on every lattice neighbour, none overlapping), bottom layer fixed; the top
/// layer pushed down by `load` [N] per ball. Small random velocities.
std::unique_ptr<Model> bonded_cube(double load) {
  auto m = std::make_unique<Model>();
  m->settings.dim = 3;
  m->settings.local_damping = 0.7;
  m->settings.margin = 0.6e-3; // lattice neighbours (gap <= 0.5 mm), no diagonals (>= 0.63 mm)
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  const int g = m->group_index("rock");
  std::int64_t id = 1;
  for (int i = 0; i < kSide; ++i)
    for (int j = 0; j < kSide; ++j)
      for (int k = 0; k < kSide; ++k) {
        const double r = 1e-3 * (0.75 + 0.25 * u(rng));
        const std::size_t b = m->balls.add(3, id++, kA * Vec3(i, j, k), r, 2650, g);
        m->balls.vel[b] = 1e-3 * Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
        if (k == 0) { // held still
          m->balls.fixity[b] = 0x3f;
          m->balls.vel[b].setZero();
        }
        if (k == kSide - 1)
          m->balls.applied_force[b] = Vec3(0, 0, -load);
      }
  LinearPBondProps p;
  p.linear.emod = 1e9;
  p.linear.kratio = 2;
  p.linear.fric = 0.5;
  p.pb_emod = 1e9;
  p.pb_kratio = 2;
  p.pb_ten = p.pb_coh = 1e12;
  p.bond = true;
  p.bond_gap_hi = 1e-3;
  ModelRule rule;
  rule.props = p;
  m->rules.push_back(rule);
  m->initialize();
  return m;
}

double kinetic(const Model& m) {
  return m.energy().kinetic();
}

} // namespace

TEST(DensityScaling, RaisesTheStepToTheQuantileAndKeepsEachGrainsKineticEnergy) {
  auto m = bonded_cube(0);
  m->cycle(1);
  const double dt0 = m->timestep();
  const double ke0 = kinetic(*m);
  const DensityScaling d = m->scale_density(0.5);
  EXPECT_TRUE(m->density_scaled());
  EXPECT_NEAR(kinetic(*m), ke0, 1e-12 * ke0); // velocities scaled with the inertia
  // Half the free grains at most are raised (the median's own step is the target), and the
  // step gains what the spread of the grains' own steps allows (radii 0.75-1.0 mm: > 10 %).
  EXPECT_GT(d.scaled, 0U);
  EXPECT_LE(d.scaled, static_cast<std::size_t>(kSide * kSide * kSide) / 2 + 1);
  EXPECT_GT(d.step_gain, 1.1);
  EXPECT_GE(d.max_factor, d.step_gain * d.step_gain * (1 - 1e-9));
  for (std::size_t i = 0; i < m->balls.size(); ++i) {
    EXPECT_GE(m->inertial_mass(i), m->balls.mass[i]);
    EXPECT_GE(m->inertial_inertia(i), m->balls.inertia[i]);
  }
  m->cycle(1);
  EXPECT_TRUE(near_rel(m->timestep(), dt0 * d.step_gain, 0.02));
  // Off again: the true inertia, the same kinetic energy, the old step.
  const double ke1 = kinetic(*m);
  const DensityScaling off = m->scale_density(0);
  EXPECT_FALSE(m->density_scaled());
  EXPECT_EQ(off.scaled, 0U);
  EXPECT_NEAR(kinetic(*m), ke1, 1e-12 * ke1);
  m->cycle(1);
  EXPECT_TRUE(near_rel(m->timestep(), dt0, 0.02));
  EXPECT_THROW(m->scale_density(1.0), std::invalid_argument);
}

TEST(DensityScaling, TheEnergyLedgerStaysClosed) {
  // The cube under a suddenly applied load: the ledger's error is the time integration's (it
  // grows with the step while the load rings through the cube and stays once it settles).
  auto errors = [](double quantile) {
    auto m = bonded_cube(2.0);
    double gain = 1;
    if (quantile > 0)
      gain = m->scale_density(quantile).step_gain;
    double worst = 0;
    for (int k = 0; k < 40; ++k) {
      m->cycle(100);
      const EnergyLedger e = m->energy();
      worst = std::max(worst, std::abs(e.balance_error()) / e.body_work);
    }
    const EnergyLedger e = m->energy();
    EXPECT_GT(e.body_work, 0); // the load did work
    return std::array<double, 3>{worst, std::abs(e.balance_error()) / e.body_work, gain};
  };
  const auto ref = errors(0), scaled = errors(0.5);
  EXPECT_LT(ref[0], 1e-3);
  EXPECT_LT(scaled[0], ref[0] * scaled[2] * scaled[2]); // first order in the step, or better
  EXPECT_LT(scaled[1], 1e-5);
}

TEST(DensityScaling, ALoadedPackingComesToTheSameEquilibrium) {
  // Statics do not depend on inertia: with and without scaling the cube settles under its load
  // to the same positions.
  auto settle = [](double quantile, std::int64_t& steps) {
    auto m = bonded_cube(2.0);
    const std::vector<Vec3> x0 = m->balls.pos;
    if (quantile > 0)
      m->scale_density(quantile);
    steps = 0;
    while (m->mean_unbalanced_force_ratio() > 1e-9 && steps < 400000) {
      m->cycle(100);
      steps += 100;
    }
    std::vector<Vec3> u(x0.size());
    for (std::size_t i = 0; i < x0.size(); ++i)
      u[i] = m->balls.pos[i] - x0[i];
    return u;
  };
  std::int64_t n_ref = 0, n_scaled = 0;
  const std::vector<Vec3> a = settle(0, n_ref), b = settle(0.5, n_scaled);
  double umax = 0, diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    umax = std::max(umax, a[i].norm());
    diff = std::max(diff, (a[i] - b[i]).norm());
  }
  EXPECT_GT(umax, 1e-9); // the load moved the top
  EXPECT_LT(diff, 1e-4 * umax) << "settled in " << n_ref << " and " << n_scaled << " steps";
}

TEST(DensityScaling, ASavedModelKeepsItsScaling) {
  auto m = bonded_cube(0);
  m->scale_density(0.5);
  m->cycle(10);
  const std::filesystem::path file = test::scratch_root() / "scaled.rlspec";
  save_model(*m, file.string(), {});
  std::unique_ptr<Model> back = load_model(file.string());
  ASSERT_TRUE(back->density_scaled());
  for (std::size_t i = 0; i < m->balls.size(); ++i) {
    EXPECT_EQ(back->inertial_mass(i), m->inertial_mass(i));
    EXPECT_EQ(back->inertial_inertia(i), m->inertial_inertia(i));
  }
  m->cycle(50);
  back->cycle(50);
  for (std::size_t i = 0; i < m->balls.size(); ++i)
    EXPECT_EQ(back->balls.pos[i], m->balls.pos[i]); // the continued run is the same run
  // Removing balls ends the scaling (the factors belonged to the old balls).
  std::vector<bool> remove(m->balls.size(), false);
  remove[3] = true;
  m->remove_balls(remove);
  EXPECT_FALSE(m->density_scaled());
}

namespace {
// A UCS on the small 3D flat-jointed card with these loading keys; its results.json.
nlohmann::json run_small_ucs(const std::string& name, const nlohmann::json& loading,
                             int expect_status = 0, std::string* msg_out = nullptr) {
  namespace fs = std::filesystem;
  nlohmann::json p = {
      {"test", "ucs"},
      {"units", "SI"},
      {"specimen", {{"material", test::source_dir() + "/tests/data/lab_3d_fj.json"}}},
      {"output", {{"vtk", false}, {"plots", false}}}};
  if (!loading.empty())
    p["loading"] = loading;
  const fs::path file = test::scratch_root() / (name + ".json");
  std::ofstream(file) << p.dump(2);
  const fs::path out = test::scratch_root() / name;
  fs::remove_all(out);
  std::string msg;
  EXPECT_EQ(test::run_command(
                test::binary() + " test " + file.string() + " -o " + out.string() + " -q", &msg),
            expect_status)
      << msg;
  if (msg_out)
    *msg_out = msg;
  if (expect_status != 0)
    return {};
  return nlohmann::json::parse(test::read_file(out / "results.json"));
}
double loading_steps(const nlohmann::json& r) {
  return r["peak_step"].get<double>() - r["load_start_step"].get<double>();
}
} // namespace

TEST(DensityScaling, AUcsTestTakesFewerStepsForTheSameElasticResponse) {
  // The small 3D flat-jointed card, UCS with and without `loading.density_scaling`: a longer step
  // (results.json says by how much), fewer loading steps to the peak, the same E and nu.
  auto run = [](const std::string& name, double quantile) {
    return run_small_ucs(name, quantile > 0 ? nlohmann::json{{"density_scaling", quantile}}
                                            : nlohmann::json::object());
  };
  const nlohmann::json ref = run("ds_ref", 0), fast = run("ds_fast", 0.5);
  EXPECT_FALSE(ref.contains("density_scaling"));
  ASSERT_TRUE(fast.contains("density_scaling"));
  const double gain = fast["density_scaling"]["timestep_gain"].get<double>();
  EXPECT_GT(gain, 1.1);
  EXPECT_LT(loading_steps(fast), loading_steps(ref) / 1.1);
  EXPECT_TRUE(near_rel(fast["youngs_modulus_Pa"].get<double>(),
                       ref["youngs_modulus_Pa"].get<double>(), 0.01));
  EXPECT_NEAR(fast["poisson_ratio"].get<double>(), ref["poisson_ratio"].get<double>(), 0.01);
  EXPECT_TRUE(
      near_rel(fast["peak_stress_Pa"].get<double>(), ref["peak_stress_Pa"].get<double>(), 0.05));
}

TEST(DensityScaling, ALargerStepFactorForTheLoadingTakesFewerSteps) {
  // `loading.timestep_safety` replaces the specimen's factor (0.8) from the start of loading:
  // results.json reports it, the loading takes about 0.8/1.2 of the steps to the peak, and the
  // elastic response and the strength stay (docs/results.md, "Time-step factor"); outside
  // (0, 1.6] it is an input error naming the key and the range.
  const nlohmann::json ref = run_small_ucs("dt_ref", nlohmann::json::object());
  const nlohmann::json fast = run_small_ucs("dt_fast", {{"timestep_safety", 1.2}});
  EXPECT_EQ(ref["timestep_safety"].get<double>(), 0.8);
  EXPECT_EQ(fast["timestep_safety"].get<double>(), 1.2);
  EXPECT_EQ(fast["load_start_step"], ref["load_start_step"]); // the seating kept its step
  EXPECT_LT(loading_steps(fast), loading_steps(ref) / 1.3);
  EXPECT_TRUE(near_rel(fast["youngs_modulus_Pa"].get<double>(),
                       ref["youngs_modulus_Pa"].get<double>(), 0.01));
  EXPECT_TRUE(
      near_rel(fast["peak_stress_Pa"].get<double>(), ref["peak_stress_Pa"].get<double>(), 0.05));
  std::string msg;
  run_small_ucs("dt_bad", {{"timestep_safety", 1.7}}, 2, &msg);
  EXPECT_NE(msg.find("loading.timestep_safety"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1.6"), std::string::npos) << msg;
}
