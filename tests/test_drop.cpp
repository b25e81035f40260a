// Drop (impact) test protocol (thesis chapters 5-6): restitution of a dropped rock against the
// closed form of Eq. 30, the RocFall calibration (Eq. 35), rebound rotation of a tilted clump,
// and bad drop protocols.
#include "helpers.hpp"

#include "contact/power_plastic.hpp"
#include "lab/protocols/drop.hpp"

#include <nlohmann/json.hpp>

#include <cmath>

using namespace rocklab;
using rocklab::test::near_rel;
namespace fs = std::filesystem;

namespace {

nlohmann::json drop_card(double b, std::vector<double> speeds) {
  return {
      {"test", "drop"},
      {"units", "SI"},
      {"dimension", 3},
      {"rock", {{"template", "single"}, {"radius", 0.04}, {"density", 2600}}},
      {"contact",
       {{"model", "powerplastic"},
        {"properties",
         {{"pp_kn", 6.4e10}, {"pp_ks", 9.6e9}, {"pp_fric", 0.5}, {"pp_T", 3500}, {"pp_b", b}}}}},
      {"impact_speeds", speeds}};
}

} // namespace

TEST(DropTest, BallRestitutionMatchesEquation30) {
  const double m = 2600 * 4.0 / 3.0 * M_PI * std::pow(0.04, 3);
  for (double b : {1.0, 5.0, 20.0}) {
    nlohmann::json j = drop_card(b, {0.5, 4.0});
    j["gravity"] = 0; // Eq. 30 has no gravity
    const DropProtocol p = drop_protocol_from_json(j, "card.json");
    for (double v : p.speeds) {
      const DropResult r = run_drop(p, v);
      ASSERT_TRUE(r.rebounded);
      EXPECT_TRUE(near_rel(r.v_impact, v, 1e-9));
      const double closed = powerplastic::restitution(m, v, 6.4e10, 3500, b);
      EXPECT_TRUE(near_rel(r.e_velocity, closed, 0.01)) << "b " << b << " v " << v;
      EXPECT_TRUE(near_rel(r.e_energy, r.e_velocity, 1e-6)); // no rotation, no tangential motion
      // the energy that did not come back went into plastic work
      EXPECT_TRUE(near_rel(r.plastic, r.ke_before - r.ke_after, 2e-3));
    }
  }
}

TEST(DropTest, CalibratedExponentFollowsTheRocfallLaw) {
  nlohmann::json j = drop_card(4.5, {2.0, 12.0});
  j["calibrate"] = {{"parameter", "exponent"}, {"R_N", 0.53}, {"V_half", 9.144}};
  const DropProtocol p = drop_protocol_from_json(j, "card.json");
  const fs::path out = test::scratch_root() / "drop_cal";
  fs::remove_all(out);
  const nlohmann::json r = run_drop_test(p, out.string(), false, nullptr);
  ASSERT_EQ(r["drops"].size(), 2u);
  double b_prev = 0;
  for (const auto& d : r["drops"]) {
    const double v = d["impact_speed_m_s"].get<double>();
    const double target = 0.53 / (1 + std::pow(v / 9.144, 2)); // Eq. 35
    EXPECT_TRUE(near_rel(d["restitution_energy"].get<double>(), target, 2e-3)) << v;
    // b rises with speed: faster rocks must lose more
    EXPECT_GT(d["exponent"].get<double>(), b_prev);
    b_prev = d["exponent"].get<double>();
  }
  EXPECT_LT(r["calibration"]["worst_bounce_velocity_error"].get<double>(), 0.05);
  for (const char* f :
       {"results.json", "restitution.csv", "history.csv", "restitution.svg", "exponent.svg"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
}

TEST(DropTest, TiltedClumpReboundsSpinning) {
  nlohmann::json j = drop_card(3, {3.0});
  j["rock"] = {
      {"template", "triangle3"}, {"radius", 0.04}, {"density", 2600}, {"rotation", {90, 20, 0}}};
  const DropProtocol p = drop_protocol_from_json(j, "card.json");
  const DropResult r = run_drop(p, 3.0);
  ASSERT_TRUE(r.rebounded);
  EXPECT_GT(r.spin, 1.0);                // the off-centre impact turns the rock
  EXPECT_GT(r.ke_rotational_after, 0.0); // and part of the rebound energy is rotation
  EXPECT_GT(r.e_energy, r.e_velocity);   // energy restitution counts it, velocity does not
  EXPECT_GT(r.slip + r.plastic, 0.0);
}

TEST(DropTest, BadDropProtocolsFailClearlyAndWriteNothing) {
  struct Case {
    nlohmann::json j;
    const char* message;
  };
  nlohmann::json neg = drop_card(2, {-1.0});
  nlohmann::json no_rock = drop_card(2, {1.0});
  no_rock.erase("rock");
  nlohmann::json cal_linear = drop_card(2, {1.0});
  cal_linear["contact"] = {{"model", "linear"}, {"properties", {{"kn", 1e6}}}};
  cal_linear["calibrate"] = nlohmann::json::object();
  nlohmann::json gap = drop_card(2, {0.01});
  gap["release_gap"] = 0.01;
  const std::vector<Case> cases{{neg, "impact_speeds[0]"},
                                {no_rock, "key 'rock'"},
                                {cal_linear, "calibrate"},
                                {gap, "key 'release_gap'"}};
  for (const Case& k : cases) {
    const fs::path file = test::scratch_root() / "bad_drop.json";
    std::ofstream(file) << k.j.dump();
    const fs::path out = test::scratch_root() / "bad_drop_out";
    std::string msg;
    EXPECT_EQ(
        test::run_command(test::binary() + " test " + file.string() + " -o " + out.string(), &msg),
        2)
        << msg;
    EXPECT_NE(msg.find(k.message), std::string::npos) << msg;
    EXPECT_FALSE(fs::exists(out)) << k.j.dump();
  }
}

TEST(DropTest, BondedRockBreaksIntoFragments) {
  // Three contact-bonded pebbles (not a clump): weak bonds break at a 10 m/s impact, strong
  // ones hold; fragment masses add up to the rock.
  const double pebble = 2600 * 4.0 / 3.0 * M_PI * std::pow(0.04, 3);
  for (double tenf : {50.0, 1e9}) {
    nlohmann::json j = drop_card(4.5, {10.0});
    j["rock"] = {{"template", "triangle3"},
                 {"radius", 0.04},
                 {"density", 2600},
                 {"rotation", {90, 0, 0}},
                 {"bond",
                  {{"model", "contactbond"},
                   {"properties",
                    {{"kn", 6.4e10},
                     {"ks", 9.6e9},
                     {"fric", 0.5},
                     {"cb_tenf", tenf},
                     {"cb_shearf", 2 * tenf}}}}}};
    const DropProtocol p = drop_protocol_from_json(j, "card.json");
    ASSERT_TRUE(p.bonded);
    const DropResult r = run_drop(p, 10.0);
    ASSERT_TRUE(r.rebounded);
    double total = 0;
    for (double f : r.fragments)
      total += f;
    EXPECT_TRUE(near_rel(total, 3 * pebble, 1e-12));
    if (tenf < 1e3) {
      EXPECT_EQ(r.bonds_broken, 3);
      EXPECT_EQ(r.fragments.size(), 3u);
      EXPECT_GT(r.bond_break, 0);
    } else {
      EXPECT_EQ(r.bonds_broken, 0);
      EXPECT_EQ(r.fragments.size(), 1u);
    }
    EXPECT_TRUE(near_rel(r.e_energy, 0.4236, 0.01)); // the platen contact still sets e
  }
}
