// Calibration: the stages on a cheap synthetic rock with a known answer (every parameter 2x off,
// 0.5 % noise, the acceptance tolerances in at most 40 evaluations); the calibration file, good and
// bad; rocklab calibrate end to end on a tiny specimen, interrupted and resumed from its cache.
#include "lab/calibration/evaluator.hpp"
#include "lab/calibration/stages.hpp"

#include "helpers.hpp"
#include "io/input_error.hpp"
#include "lab/calibration/calibration_file.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <random>
#include <regex>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

using namespace rocklab::calibration;

// The properties the stages steer, by the roles their tests declare (lab/protocols/ucs.cpp).
constexpr const char* kYoungs = "youngs_modulus_Pa";
constexpr const char* kPoisson = "poisson_ratio";
constexpr const char* kUcs = "ucs_Pa";

namespace {

// Parameters: 0 modulus [Pa], 1 stiffness ratio, 2 tensile strength [Pa] (cohesion = r x it),
// 3 r = cohesion / tension, 4 slit fraction.
Measured synthetic_rock(const std::vector<double>& v, double noise, std::mt19937& rng) {
  const double emod = v[0], kr = v[1], ten = v[2], r = v[3], f = v[4];
  std::normal_distribution<double> n(0.0, noise);
  auto nz = [&](double x) { return x * (1 + n(rng)); };
  Measured m;
  m[kYoungs] = nz(emod * 0.7 / (1 + 0.1 * kr));
  m[kPoisson] = nz(0.05 + 0.11 * std::log(kr));
  m[kUcs] = nz(ten * (2 + 0.9 * r) * (1 - 0.5 * f));
  m["bts_Pa"] = nz(ten * (0.8 + 0.02 * r) * (1 - 0.2 * f));
  m["direct_tension_Pa"] = nz(ten * 0.9 * (1 - 0.3 * f));
  m["ucs_over_bts"] = m[kUcs] / m["bts_Pa"];
  m["crack_initiation_over_ucs"] = nz(0.25 + 0.5 * f + 0.005 * r);
  // Each mean's standard error (the noise's size: a mean over seeds with that scatter), so that a
  // target within its tolerance is confirmed (stages.hpp, target_confirmed).
  for (const std::string k : {kYoungs, kPoisson, kUcs, "bts_Pa", "direct_tension_Pa",
                              "ucs_over_bts", "crack_initiation_over_ucs"})
    m[se_key(k)] = noise * std::abs(m[k]);
  return m;
}

// The synthetic rock's five parameters with their bounds, the shape parameters off by 2x.
std::vector<Param> synthetic_params(double emod, double kratio, double ten) {
  return {{"emod", Role::Modulus, 1e9, 1e12, emod},
          {"kratio", Role::StiffnessRatio, 1.0, 8.0, kratio},
          {"ten", Role::Strength, 1e6, 1e9, ten},
          {"coh_over_ten", Role::Shape, 1.0, 20.0, 16.0},
          {"slit", Role::Shape, 0.0, 0.5, 0.4}};
}

} // namespace

TEST(Calibration, StagesFindAKnownRockFromTwiceWrongParametersWithNoise) {
  const std::vector<double> truth{6e10, 2.5, 2e7, 8.0, 0.2};
  std::mt19937 rng_truth(1);
  const Measured want = synthetic_rock(truth, 0.0, rng_truth);
  const std::vector<Target> targets{
      {kYoungs, want.at(kYoungs), 0.03},
      {kPoisson, want.at(kPoisson), 0.03},
      {kUcs, want.at(kUcs), 0.05},
      {"bts_Pa", want.at("bts_Pa"), 0.08},
      {"direct_tension_Pa", want.at("direct_tension_Pa"), 0.08},
      {"ucs_over_bts", want.at("ucs_over_bts"), 0.10},
      {"crack_initiation_over_ucs", want.at("crack_initiation_over_ucs"), 0.05}};
  std::vector<Param> params = synthetic_params(1.2e11, 5.0, 4e7);
  std::mt19937 rng(7);
  std::vector<Stage> seen;
  const Evaluate evaluate = [&](const std::vector<double>& v, Stage s) {
    seen.push_back(s);
    return synthetic_rock(v, 0.005, rng);
  };
  const Outcome out = calibrate(params, targets, evaluate, Budget{});
  ASSERT_FALSE(out.history.empty());
  std::printf("synthetic calibration: %zu evaluations;", out.history.size());
  for (const Param& q : out.params)
    std::printf(" %s %.4g", q.name.c_str(), q.value);
  std::printf("\n");
  EXPECT_LE(out.history.size(), 40u);
  EXPECT_TRUE(out.met);
  for (const Target& t : targets)
    EXPECT_LE(std::abs(t.error(out.measured.at(t.property))), 1.0)
        << t.property << " " << out.measured.at(t.property) << " against " << t.value;
  // The stages ran in order (elastic, strength, ratios, then the polish) and ended with every
  // test measured.
  EXPECT_EQ(seen.front(), Stage::Elastic);
  EXPECT_NE(std::find(seen.begin(), seen.end(), Stage::Strength), seen.end());
  EXPECT_NE(std::find(seen.begin(), seen.end(), Stage::Ratios), seen.end());
  EXPECT_TRUE(out.history.back().stage == Stage::Final ||
              out.history.back().stage == Stage::Ratios ||
              out.history.back().stage == Stage::Strength);
  // The answer is unique here: the parameters come back near the truth.
  for (std::size_t i = 0; i < truth.size(); ++i)
    EXPECT_NEAR(out.params[i].value / truth[i], 1.0, 0.15) << out.params[i].name;
}

TEST(Calibration, ScatterInPoissonsRatioDoesNotThrowTheStiffnessRatioAcrossItsRange) {
  // The 2D acceptance run: nu 0.2494 and then 0.2502 a few per cent of stiffness ratio apart (the
  // seeds' scatter), target 0.26; the near-flat secant once made the next step a factor 2 (nu
  // 0.36).
  std::vector<Param> params = synthetic_params(6e10, 2.0, 2e7);
  std::vector<double> kr;
  const Evaluate evaluate = [&](const std::vector<double>& v, Stage) {
    kr.push_back(v[1]);
    Measured m;
    m[kYoungs] = 6.9e10;
    m[kPoisson] = kr.size() == 1 ? 0.2494 : kr.size() == 2 ? 0.2502 : 0.26;
    return m;
  };
  const std::vector<Target> targets{{kYoungs, 6.9e10, 0.03}, {kPoisson, 0.26, 0.03}};
  Budget b;
  b.strength = b.ratios = b.polish = 0;
  calibrate(params, targets, evaluate, b);
  ASSERT_GE(kr.size(), 3u);
  EXPECT_LT(kr[2] / kr[1], 1.3) << kr[0] << " " << kr[1] << " " << kr[2];
  EXPECT_GT(kr[2] / kr[1], 1.0); // still towards the target
}

TEST(Calibration, AnInertShapeParameterIsNamedAndAloneStopsTheStage) {
  // A rock whose joints all break in tension: the cohesion/tension ratio moves nothing. A stage 3
  // with only that parameter free once spent its whole budget (COBYLA, 20 evaluations of 10
  // minutes); it now stops after the step that shows it inert and says so.
  std::mt19937 rng_truth(1);
  const Measured want = synthetic_rock({6e10, 2.5, 2e7, 8.0, 0.2}, 0.0, rng_truth);
  // UCS/BTS out of the ratio's reach (it does not act) and of the slits' (not free here).
  const std::vector<Target> targets{{kUcs, want.at(kUcs), 0.05},
                                    {"ucs_over_bts", 1.3 * want.at("ucs_over_bts"), 0.10}};
  int ratio_calls = 0;
  auto inert_r = [&](std::vector<double> v, Stage s) {
    ratio_calls += s == Stage::Ratios;
    v.resize(5, 0.4); // no slit parameter: the fraction stays 2x off
    v[3] = 8.0;       // the ratio does not act
    std::mt19937 rng(2);
    return synthetic_rock(v, 0.0, rng);
  };
  std::vector<Param> one = synthetic_params(6e10, 2.5, 2e7);
  one.pop_back();
  const Outcome a = calibrate(one, targets, inert_r, Budget{});
  EXPECT_EQ(ratio_calls, 2);
  ASSERT_EQ(a.notes.size(), 2u);
  EXPECT_NE(a.notes[0].find("coh_over_ten moved from 16 to"), std::string::npos) << a.notes[0];
  EXPECT_NE(a.notes[0].find("inert"), std::string::npos) << a.notes[0];
  EXPECT_NE(a.notes[1].find("every shape parameter is inert"), std::string::npos);
  // With the slit fraction free as well, the inert ratio is named and the search goes on with the
  // slits, which meet the target.
  ratio_calls = 0;
  auto inert_r_slit = [&](std::vector<double> v, Stage) {
    v[3] = 8.0;
    std::mt19937 rng(2);
    return synthetic_rock(v, 0.0, rng);
  };
  const std::vector<Target> reachable{
      {kUcs, want.at(kUcs), 0.05},
      {"ucs_over_bts", want.at("ucs_over_bts"), 0.10},
      {"crack_initiation_over_ucs", want.at("crack_initiation_over_ucs"), 0.05, true}};
  const Outcome b = calibrate(synthetic_params(6e10, 2.5, 2e7), reachable, inert_r_slit, Budget{});
  ASSERT_FALSE(b.notes.empty());
  EXPECT_NE(b.notes[0].find("coh_over_ten"), std::string::npos) << b.notes[0];
  for (const std::string& n : b.notes)
    EXPECT_EQ(n.find("slit"), std::string::npos) << n;
  EXPECT_TRUE(b.met);
}

TEST(Calibration, StageThreeKeepsThePointThatMeetsEveryTargetOverACloserMiss) {
  // As in the Berea campaign: stage 3's second point misses the BTS target with the smallest sum
  // of squared errors (0.06, -1.18 tolerances), its third meets both (-0.8, -0.92). The stage
  // stops at the third and must hand that one to the polish.
  const std::vector<Target> targets{{kYoungs, 1.6e10, 0.05},
                                    {kPoisson, 0.28, 0.03, true},
                                    {kUcs, 4e7, 0.05},
                                    {"bts_Pa", 4e6, 0.25}};
  const std::vector<std::pair<double, double>> stage3{// (nu, BTS) of each stage-3 point
                                                      {0.28, 2.6e6},
                                                      {0.2818, 2.82e6},
                                                      {0.256, 3.08e6}};
  std::vector<std::vector<double>> asked;
  double bts_now = 2.6e6;
  auto rock = [&](const std::vector<double>& v, Stage s) {
    Measured m{{kYoungs, 1.6e10}, {kPoisson, 0.28}, {kUcs, 4e7}, {"bts_Pa", bts_now}};
    if (s == Stage::Ratios) {
      const std::size_t k = std::min(asked.size(), stage3.size() - 1);
      asked.push_back(v);
      m[kPoisson] = stage3[k].first;
      m["bts_Pa"] = bts_now = stage3[k].second;
    }
    return m;
  };
  const std::vector<Param> params{{"emod", Role::Modulus, 1e9, 1e12, 5e10},
                                  {"kratio", Role::StiffnessRatio, 1.0, 20.0, 14.0},
                                  {"ten", Role::Strength, 1e6, 1e9, 4e7},
                                  {"gapped", Role::Shape, 0.0, 0.45, 0.1},
                                  {"slit", Role::Shape, 0.0, 0.45, 0.1}};
  const Outcome out = calibrate(params, targets, rock, Budget{});
  ASSERT_EQ(asked.size(), 3u); // stopped at the point that met both
  EXPECT_NE(asked[1], asked[2]);
  EXPECT_EQ(out.params[3].value, asked[2][3]);
  EXPECT_EQ(out.params[4].value, asked[2][4]);
}

TEST(Calibration, StageThreeDoesNotTakeAStepWithinTheNoiseAsProgress) {
  // Stage 3's points miss the BTS target by 2.0, 1.85 and 1.2 tolerances, each mean with a
  // standard error of 0.2 tolerances (sums of squares 4 +- 0.8, 3.42 +- 0.74, 1.44 +- 0.48). The
  // second is no better than the first within the noise: after two points the first is kept; the
  // third is better by more than twice the noise and replaces it.
  const std::vector<Target> targets{{kUcs, 4e7, 0.05}, {"bts_Pa", 4e6, 0.1}};
  const std::vector<double> errs{2.0, 1.85, 1.2};
  for (int budget : {2, 3}) {
    std::vector<std::vector<double>> asked;
    auto rock = [&](const std::vector<double>& v, Stage s) {
      Measured m{{kUcs, 4e7}, {"bts_Pa", 4e6 * 1.2}, {se_key("bts_Pa"), 4e6 * 0.02}};
      if (s == Stage::Ratios) {
        m["bts_Pa"] = 4e6 * (1 + 0.1 * errs[std::min(asked.size(), errs.size() - 1)]);
        asked.push_back(v);
      }
      return m;
    };
    const std::vector<Param> params{{"ten", Role::Strength, 1e6, 1e9, 4e7},
                                    {"gapped", Role::Shape, 0.0, 0.45, 0.1},
                                    {"slit", Role::Shape, 0.0, 0.45, 0.1}};
    Budget b;
    b.ratios = budget;
    const Outcome out = calibrate(params, targets, rock, b);
    ASSERT_EQ(asked.size(), static_cast<std::size_t>(budget));
    ASSERT_NE(asked[0], asked[1]);
    const std::size_t kept = budget == 2 ? 0 : 2;
    EXPECT_EQ(out.params[1].value, asked[kept][1]) << "budget " << budget;
    EXPECT_EQ(out.params[2].value, asked[kept][2]) << "budget " << budget;
    const bool noted = std::any_of(out.notes.begin(), out.notes.end(), [](const std::string& n) {
      return n.find("not progress") != std::string::npos;
    });
    EXPECT_TRUE(noted) << "budget " << budget;
  }
}

TEST(Calibration, ASeedWithoutAMeasurementDoesNotBlankTheEvaluation) {
  // A Brazilian disk that never split on one seed: its BTS is null there.
  const std::map<std::string, std::vector<double>> all{
      {"bts_Pa", {2e7, std::nan(""), 3e7}},
      {"ucs_Pa", {1e8, 2e8, 3e8}},
      {"friction_angle_deg", {std::nan(""), std::nan(""), std::nan("")}}};
  Evaluation ev;
  const std::vector<std::string> partial = average_replicates(all, ev);
  EXPECT_DOUBLE_EQ(ev.mean["bts_Pa"], 2.5e7);
  EXPECT_NEAR(ev.sd["bts_Pa"], std::sqrt(0.5e14), 1e-3);
  EXPECT_DOUBLE_EQ(ev.mean["ucs_Pa"], 2e8);
  EXPECT_TRUE(std::isnan(ev.mean["friction_angle_deg"])); // no seed measured it: not measured
  EXPECT_EQ(partial, std::vector<std::string>{"bts_Pa"});
}

TEST(Calibration, AnErrorInTheOptimiserStageIsNotSwallowed) {
  // NLopt's wrapper turns an exception from the objective into a generic failure; an interrupt or
  // a test that rejects its input during stage 3 must still stop the campaign with its own error.
  const std::vector<Param> params = synthetic_params(6e10, 2.5, 2e7);
  std::mt19937 rng_truth(1);
  const Measured want = synthetic_rock({6e10, 2.5, 2e7, 8.0, 0.2}, 0.0, rng_truth);
  const std::vector<Target> targets{{kUcs, want.at(kUcs), 0.05},
                                    {"ucs_over_bts", want.at("ucs_over_bts"), 0.10}};
  std::mt19937 rng(3);
  int ratio_calls = 0;
  const Evaluate evaluate = [&](const std::vector<double>& v, Stage s) {
    if (s == Stage::Ratios && ++ratio_calls == 2)
      throw rocklab::InputError("cal.json: test 'brazilian' rejected its input");
    return synthetic_rock(v, 0.0, rng);
  };
  try {
    calibrate(params, targets, evaluate, Budget{});
    ADD_FAILURE() << "calibrate returned";
  } catch (const rocklab::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rejected its input"), std::string::npos);
  }
  EXPECT_EQ(ratio_calls, 2);
}

TEST(Calibration, ErrorsAreInTolerancesAndBoundsHold) {
  const Target rel{kUcs, 200e6, 0.05};
  EXPECT_DOUBLE_EQ(rel.error(210e6), 1.0);
  EXPECT_DOUBLE_EQ(rel.error(190e6), -1.0);
  const Target abs{kPoisson, 0.26, 0.03, true};
  EXPECT_NEAR(abs.error(0.29), 1.0, 1e-12);
  EXPECT_TRUE(std::isinf(abs.error(std::nan(""))));
  // A target out of reach: the parameters stop at their bounds and `met` is false.
  std::vector<Param> params{{"emod", Role::Modulus, 1e9, 2e9, 1.5e9}};
  const Evaluate evaluate = [](const std::vector<double>& v, Stage) {
    return Measured{{kYoungs, v[0]}};
  };
  const Outcome out = calibrate(params, {{kYoungs, 1e10, 0.03}}, evaluate, Budget{});
  EXPECT_FALSE(out.met);
  EXPECT_DOUBLE_EQ(out.params[0].value, 2e9);
}

// ---------------------------------------------------------------------------------------------
// The calibration file: a good one loads and maps parameters onto the card; bad ones name the key.

namespace {

nlohmann::json good_calibration() {
  return {{"name", "ldb-2d"},
          {"units", "SI"},
          {"material", rocklab::test::source_dir() + "/materials/granite_fj_2d.json"},
          {"targets",
           {{"youngs_modulus_Pa", {{"value", 69e9}, {"tolerance", 0.03}}},
            {"poisson_ratio", {{"value", 0.26}, {"tolerance", 0.03}, {"absolute", true}}},
            {"ucs_Pa", {{"value", 200e6}, {"tolerance", 0.05}}},
            {"ucs_over_bts", {{"value", 21.5}, {"tolerance", 0.1}}}}},
          {"parameters",
           {{"flatjoint.fj_emod", {{"role", "modulus"}, {"bounds", {1e10, 1e12}}}},
            {"linear.emod", {{"role", "modulus"}, {"bounds", {1e10, 1e12}}}},
            {"flatjoint.fj_kratio", {{"role", "stiffness_ratio"}, {"bounds", {1.0, 5.0}}}},
            {"flatjoint.fj_ten", {{"role", "strength"}, {"bounds", {1e6, 1e9}}}},
            {"flatjoint.fj_coh/flatjoint.fj_ten", {{"role", "shape"}, {"bounds", {1.0, 30.0}}}}}},
          {"tests",
           {{{"name", "ucs"}, {"test", "ucs"}},
            {{"name", "bz"},
             {"test", "brazilian"},
             {"shape", {{"shape", "disk"}, {"diameter", 0.025}}}}}},
          {"seeds", {1, 2, 3}}};
}

std::string write_calibration(const std::string& name, const nlohmann::json& j) {
  const std::filesystem::path p = rocklab::test::scratch_root() / (name + ".json");
  std::ofstream(p) << j.dump(2);
  return p.string();
}

std::string error_of(const nlohmann::json& j) {
  try {
    load_calibration(write_calibration("bad", j));
  } catch (const rocklab::InputError& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(CalibrationFile, ReadsTheFileAndSetsTheCard) {
  const CalibrationFile c = load_calibration(write_calibration("good", good_calibration()));
  ASSERT_EQ(c.params.size(), 5u);
  ASSERT_EQ(c.targets.size(), 4u);
  EXPECT_EQ(c.seeds.size(), 3u);
  // Parameters in key order; starts are the card's values: fj_ten mean 3.5e7, fj_coh/fj_ten
  // 3.5e8/3.5e7 = 10.
  auto find = [&](const std::string& key) {
    return std::find_if(c.params.begin(), c.params.end(),
                        [&](const CardParam& p) { return p.key == key; });
  };
  const auto ratio = find("flatjoint.fj_coh/flatjoint.fj_ten");
  ASSERT_NE(ratio, c.params.end());
  EXPECT_EQ(ratio->path, "flatjoint.fj_coh");
  EXPECT_EQ(ratio->over, "flatjoint.fj_ten");
  EXPECT_DOUBLE_EQ(ratio->param.value, 10.0);
  EXPECT_EQ(ratio->param.role, Role::Shape);
  std::vector<double> v;
  for (const CardParam& p : c.params)
    v.push_back(p.key == "flatjoint.fj_ten" ? 7e7 : p.param.value);
  v[static_cast<std::size_t>(ratio - c.params.begin())] = 5.0;
  const nlohmann::json card = apply_params(c.material, c.params, v);
  // The strength keeps its coefficient of variation (sd 7e6 of 3.5e7 -> 1.4e7 of 7e7), and the
  // ratio applies to the new tension: cohesion 5 x 7e7.
  EXPECT_DOUBLE_EQ(card["flatjoint"]["fj_ten"]["mean"].get<double>(), 7e7);
  EXPECT_NEAR(card["flatjoint"]["fj_ten"]["sd"].get<double>(), 1.4e7, 1e-3);
  EXPECT_DOUBLE_EQ(card["flatjoint"]["fj_coh"]["mean"].get<double>(), 3.5e8);
  EXPECT_NEAR(card["flatjoint"]["fj_coh"]["sd"].get<double>(), 7e7, 1e-3);
  EXPECT_DOUBLE_EQ(card["linear"]["emod"].get<double>(), 1e11);
}

TEST(CalibrationFile, AFreeSlitFractionTakesItsShareFromTheBondedOne) {
  // The granite card has bonded 0.9, gapped 0, slit 0.1; the three must keep summing to 1.
  nlohmann::json j = good_calibration();
  j["parameters"]["flatjoint.types.slit"] = {{"role", "shape"}, {"bounds", {0.0, 0.5}}};
  const CalibrationFile c = load_calibration(write_calibration("slit", j));
  std::vector<double> v;
  for (const CardParam& p : c.params)
    v.push_back(p.key == "flatjoint.types.slit" ? 0.35 : p.param.value);
  const nlohmann::json card = apply_params(c.material, c.params, v);
  EXPECT_DOUBLE_EQ(card["flatjoint"]["types"]["slit"].get<double>(), 0.35);
  EXPECT_DOUBLE_EQ(card["flatjoint"]["types"]["bonded"].get<double>(), 0.65);
  EXPECT_DOUBLE_EQ(card["flatjoint"]["types"]["gapped"].get<double>(), 0.0);
  // Bounds that would leave a negative bonded fraction are refused, naming the allowed range.
  j["parameters"]["flatjoint.types.slit"]["bounds"] = {0.0, 1.5};
  EXPECT_NE(error_of(j).find("free within [0, 1 - gapped] = [0, 1]"), std::string::npos)
      << error_of(j);
}

TEST(CalibrationFile, BadFilesNameTheKeyAndWhatIsAllowed) {
  nlohmann::json j = good_calibration();
  j["parameters"]["flatjoint.fj_nope"] = {{"role", "strength"}, {"bounds", {1, 2}}};
  EXPECT_NE(error_of(j).find("no number or {\"mean\", \"sd\"} at \"flatjoint.fj_nope\""),
            std::string::npos)
      << error_of(j);
  j = good_calibration();
  j["parameters"]["flatjoint.fj_ten"]["bounds"] = {5e7, 5e7};
  EXPECT_NE(error_of(j).find("empty bounds"), std::string::npos) << error_of(j);
  j = good_calibration();
  j["parameters"]["flatjoint.fj_ten"]["bounds"] = {1e8, 1e9};
  EXPECT_NE(error_of(j).find("outside the bounds"), std::string::npos) << error_of(j);
  j = good_calibration();
  j["targets"]["direct_tension_Pa"] = {{"value", 6.9e6}, {"tolerance", 0.08}};
  EXPECT_NE(error_of(j).find("needs 1 \"direct_tension\" test"), std::string::npos) << error_of(j);
  j = good_calibration();
  j["targets"]["ucs_mpa"] = {{"value", 200}};
  EXPECT_NE(error_of(j).find("unknown target; allowed: youngs_modulus_Pa"), std::string::npos)
      << error_of(j);
  j = good_calibration();
  j["parameters"]["flatjoint.fj_ten"]["role"] = "strenght";
  EXPECT_NE(error_of(j).find("strenght"), std::string::npos) << error_of(j);
  j = good_calibration();
  j["parameters"].erase("flatjoint.fj_ten");
  EXPECT_NE(error_of(j).find("denominator \"flatjoint.fj_ten\" must be a free parameter"),
            std::string::npos)
      << error_of(j);
  j = good_calibration();
  j["budgte"] = 3;
  EXPECT_NE(error_of(j).find("budgte"), std::string::npos) << error_of(j);
  // A ratio with an empty side (found by the seed-4 fuzz: "/flatjoint.fj_ten" crashed).
  for (const char* bad : {"/flatjoint.fj_ten", "flatjoint.fj_coh/", "/"}) {
    j = good_calibration();
    j["parameters"][bad] = {{"role", "strength"}, {"bounds", {0.1, 10}}};
    EXPECT_NE(error_of(j).find("with no empty side"), std::string::npos) << bad << error_of(j);
  }
  // A bound the model's own reader refuses (a stiffness ratio between 0 and 1e-3) is named with
  // the parameter before any genesis runs; one within its range loads.
  j = good_calibration();
  j["parameters"]["flatjoint.fj_kratio"]["bounds"] = {1e-9, 5.0};
  EXPECT_NE(error_of(j).find("parameters.flatjoint.fj_kratio.bounds"), std::string::npos)
      << error_of(j);
  EXPECT_NE(error_of(j).find("fj_kratio"), std::string::npos) << error_of(j);
  j["parameters"]["flatjoint.fj_kratio"]["bounds"] = {1e-3, 5.0};
  EXPECT_EQ(error_of(j), "");
  // A material path that is not a card is named with the calibration file's key.
  j = good_calibration();
  j["material"] = "/dev/zero";
  EXPECT_NE(error_of(j).find("key 'material': /dev/zero"), std::string::npos) << error_of(j);
}

// A variant names only what differs ("extends"): every other key is the extended file's, a key it
// gives replaces the extended one whole, and its material path is read from the file that gave it.
TEST(CalibrationFile, AVariantExtendsAFileAndReplacesWholeKeys) {
  const std::string dir = rocklab::test::source_dir() + "/lab/calibrate/";
  const CalibrationFile base = load_calibration(dir + "lac_du_bonnet.json");
  const CalibrationFile slits = load_calibration(dir + "lac_du_bonnet_slits.json");
  EXPECT_EQ(slits.name, "lac-du-bonnet-3d-slits");
  EXPECT_EQ(slits.tests, base.tests);
  EXPECT_EQ(slits.seeds, (std::vector<std::uint64_t>{1, 2, 3, 4, 5, 6})); // its own key
  EXPECT_EQ(base.seeds, (std::vector<std::uint64_t>{1, 2, 3}));
  ASSERT_EQ(slits.targets.size(), base.targets.size());
  ASSERT_EQ(slits.params.size(), base.params.size());
  EXPECT_EQ(slits.budget.ratios, 0); // its own budget, not the defaults
  EXPECT_EQ(std::filesystem::path(slits.material_file).filename(),
            "granite_fj_3d_slits_start.json");
  EXPECT_NE(slits.material, base.material);

  const std::string base_file = write_calibration("ext_base", good_calibration());
  const nlohmann::json child = {{"extends", "ext_base.json"}, {"seeds", {4, 5}}};
  const CalibrationFile c = load_calibration(write_calibration("ext_child", child));
  const CalibrationFile b = load_calibration(base_file);
  EXPECT_EQ(c.seeds, (std::vector<std::uint64_t>{4, 5}));
  EXPECT_EQ(c.tests, b.tests);
  EXPECT_EQ(c.material_file, b.material_file);
  // A missing file, a wrong type and a file extending itself name the key.
  EXPECT_NE(error_of({{"extends", "no_such.json"}}).find("key 'extends': "), std::string::npos);
  EXPECT_NE(error_of({{"extends", "no_such.json"}}).find("does not exist"), std::string::npos);
  EXPECT_NE(error_of({{"extends", 3}}).find("key 'extends': a calibration file's path"),
            std::string::npos);
  const std::string self = write_calibration("ext_self", {{"extends", "ext_self.json"}});
  try {
    load_calibration(self);
    ADD_FAILURE() << "a file extending itself loaded";
  } catch (const rocklab::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("more than 8 files deep"), std::string::npos) << e.what();
  }
  // An error in the extended file names the chain.
  nlohmann::json bad = good_calibration();
  bad["budgte"] = 1;
  write_calibration("ext_bad_base", bad);
  const std::string msg = error_of({{"extends", "ext_bad_base.json"}});
  EXPECT_NE(msg.find("budgte"), std::string::npos) << msg;
}

// ---------------------------------------------------------------------------------------------
// rocklab calibrate end to end on a tiny 2D specimen: E and UCS from a card 2-4x off; a run
// interrupted after its first evaluation resumes from the cache; a rerun runs nothing.

// A calibration of the tiny 2D flat-jointed specimen's E and UCS (its card is 2-4x off).
nlohmann::json tiny_calibration(const std::string& name, const std::vector<int>& seeds, int elastic,
                                int strength, int polish) {
  return {{"name", name},
          {"units", "SI"},
          {"material", rocklab::test::source_dir() + "/tests/data/lab_2d_fj.json"},
          {"targets",
           {{"youngs_modulus_Pa", {{"value", 3e9}, {"tolerance", 0.05}}},
            {"ucs_Pa", {{"value", 20e6}, {"tolerance", 0.05}}}}},
          {"parameters",
           {{"flatjoint.fj_emod", {{"role", "modulus"}, {"bounds", {1e8, 1e12}}}},
            {"flatjoint.fj_ten", {{"role", "strength"}, {"bounds", {1e5, 1e10}}}},
            {"flatjoint.fj_coh", {{"role", "strength"}, {"bounds", {1e5, 1e10}}}}}},
          {"tests",
           {{{"name", "ucs"}, {"test", "ucs"}, {"output", {{"vtk", false}, {"plots", false}}}}}},
          {"seeds", seeds},
          {"budget",
           {{"elastic", elastic},
            {"strength", strength},
            {"ratios", 0},
            {"polish", polish},
            {"max_seeds", static_cast<int>(seeds.size())}, // no seeds added: a quick campaign
            {"validation_rounds", 1},
            {"validation_max", 6}}}};
}

TEST(CalibrationCli, ATestThatRejectsItsInputStopsTheCampaignWithTwo) {
  // A Brazilian disk whose round vessel missed the card's porosity on one seed used to leave BTS
  // unmeasured in every evaluation while the optimiser went on. Here the UCS specimen is too small
  // for the grains: the campaign stops at once, exit 2, naming where the shape was given and why.
  namespace fs = std::filesystem;
  const fs::path dir = rocklab::test::scratch_root() / "calibrate-bad-test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  nlohmann::json j = tiny_calibration("bad-test", {1}, 2, 1, 0);
  j["tests"][0]["shape"] = {{"shape", "rectangle"}, {"width", 1e-4}, {"height", 2e-4}};
  const std::string file = (dir / "bad.json").string();
  std::ofstream(file) << j.dump(2);
  std::string msg;
  EXPECT_EQ(rocklab::test::run_command(rocklab::test::binary() + " calibrate " + file + " -o " +
                                           (dir / "out").string() + " --jobs 1",
                                       &msg),
            2)
      << msg;
  // Refused before any process starts (the estimate of each test's specimen), naming the key
  // where the shape was given, no longer after a seed's packing missed the porosity.
  EXPECT_NE(msg.find(file + ": key 'tests[0].shape': its smallest dimension"), std::string::npos)
      << msg;
  EXPECT_FALSE(fs::exists(dir / "out" / "card.json"));
}

TEST(CalibrationCli, TinyCalibrationMeetsItsTargetsAndResumesFromItsCache) {
  namespace fs = std::filesystem;
  const fs::path dir = rocklab::test::scratch_root() / "calibrate";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const nlohmann::json j = tiny_calibration("tiny", {1}, 4, 4, 1);
  const std::string file = (dir / "tiny.json").string(), out = (dir / "out").string();
  std::ofstream(file) << j.dump(2);
  // Interrupt once the first evaluation is in the cache.
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    execl(rocklab::test::binary().c_str(), "rocklab", "calibrate", file.c_str(), "-o", out.c_str(),
          "-q", "--jobs", "1", static_cast<char*>(nullptr));
    _exit(127);
  }
  auto evaluations = [&] {
    int n = 0;
    if (fs::exists(dir / "out" / "evaluations"))
      for (const auto& e : fs::directory_iterator(dir / "out" / "evaluations"))
        n += fs::exists(e.path() / "suite" / "summary.json") ? 1 : 0;
    return n;
  };
  for (int i = 0; i < 6000 && evaluations() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 130) << "the calibration finished before it was interrupted";
  const int done = evaluations();
  ASSERT_GE(done, 1);
  EXPECT_FALSE(fs::exists(dir / "out" / "card.json"));
  // Resume: the cached evaluations are reused, the targets met on the tuned seed. The exit status
  // follows the validation on fresh seeds (one tuned seed of this tiny specimen does not hold on
  // the next ones: its UCS scatters by tens of %).
  const std::string cmd =
      rocklab::test::binary() + " calibrate " + file + " -o " + out + " --jobs 1";
  auto finished = [](int status, const std::string& said) {
    return (status == 0 &&
            said.find("validation   every target met on 6 fresh seeds") != std::string::npos) ||
           (status == 1 &&
            said.find("validation   NOT every target met on 6 fresh seeds") != std::string::npos);
  };
  std::string msg;
  ASSERT_TRUE(finished(rocklab::test::run_command(cmd, &msg), msg)) << msg;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(msg, m, std::regex(R"(\((\d+) suites run, (\d+) cached\))")))
      << msg;
  EXPECT_GE(std::stoi(m[2]), done) << msg;
  EXPECT_NE(msg.find("every target met"), std::string::npos) << msg;
  const nlohmann::json card =
      nlohmann::json::parse(rocklab::test::read_file(dir / "out" / "card.json"));
  EXPECT_GT(card["flatjoint"]["fj_emod"].get<double>(), 1e9); // moved from the start
  EXPECT_NE(card["source"].get<std::string>().find("every target met"), std::string::npos);
  const std::string report = rocklab::test::read_file(dir / "out" / "report.md");
  EXPECT_NE(report.find("| youngs_modulus_Pa | 3e+09 | 5 % |"), std::string::npos) << report;
  // The sensitivity table: E follows the flat-joint modulus (the linear springs' does not move),
  // and neither strength moves E.
  std::smatch row;
  ASSERT_TRUE(std::regex_search(
      report, row, std::regex(R"(\| flatjoint\.fj_emod \| \+10 % \| (\S+) \| (\S+) \|)")))
      << report;
  EXPECT_GT(std::stod(row[2]), 0.4) << report; // columns in the order of the targets
  EXPECT_LT(std::stod(row[2]), 1.1) << report;
  ASSERT_TRUE(std::regex_search(
      report, row, std::regex(R"(\| flatjoint\.fj_ten \| \+10 % \| (\S+) \| (\S+) \|)")))
      << report;
  EXPECT_LT(std::abs(std::stod(row[2])), 0.05) << report;
  // The validation on 6 fresh seeds (the one tuned seed has no standard error, and says so), and
  // what the noise leaves of each parameter: the modulus is pinned by E, the cohesion moves no
  // target (every joint breaks in tension).
  EXPECT_NE(report.find("## Validation on fresh seeds"), std::string::npos) << report;
  EXPECT_TRUE(std::regex_search(
      report,
      std::regex(
          R"(\| ucs_Pa \| 2e\+07 \| 5 % \| \S+ \(one value: no standard error\) \| \S+ ± \S+ \| [-+]\d)")))
      << report;
  EXPECT_NE(report.find("(1001, 1002, 1003, 1004, 1005, 1006)"), std::string::npos) << report;
  EXPECT_TRUE(
      std::regex_search(report, std::regex(R"(\| flatjoint\.fj_emod \| \S+ \| \S+ % \| yes \|)")))
      << report;
  EXPECT_TRUE(
      std::regex_search(report, std::regex(R"(\| flatjoint\.fj_coh \| \S+ \| — \| \*\*no\*\*)")))
      << report;
  const std::string svg = rocklab::test::read_file(dir / "out" / "convergence.svg");
  EXPECT_NE(svg.find("<polyline"), std::string::npos);
  // The fitted card is a valid material card, and a rerun runs nothing and writes the same card.
  ASSERT_TRUE(finished(rocklab::test::run_command(cmd, &msg), msg)) << msg;
  EXPECT_NE(msg.find("(0 suites run"), std::string::npos) << msg;
  EXPECT_EQ(nlohmann::json::parse(rocklab::test::read_file(dir / "out" / "card.json")), card);
  // A replicate whose test rejected its input (exit 2: it stopped the campaign, e.g. a packing
  // cache an older rocklab could not read back) is run again on resume, not replayed as a failure.
  const fs::path first = fs::directory_iterator(dir / "out" / "evaluations")->path();
  nlohmann::json sm =
      nlohmann::json::parse(rocklab::test::read_file(first / "suite" / "summary.json"));
  sm["tests"][0]["status"] = "failed";
  sm["tests"][0]["exit_status"] = 2;
  sm["tests"][0]["error"] = "rocklab: input error: an old rejection";
  std::ofstream(first / "suite" / "summary.json") << sm.dump(2);
  ASSERT_TRUE(finished(rocklab::test::run_command(cmd, &msg), msg)) << msg;
  EXPECT_NE(msg.find("(1 suites run"), std::string::npos) << msg;
  EXPECT_EQ(nlohmann::json::parse(rocklab::test::read_file(dir / "out" / "card.json")), card);
  ASSERT_EQ(rocklab::test::run_command(rocklab::test::binary() + " genesis " + out +
                                       "/card.json -o " + out + "/fitted.rlspec -q"),
            0);
}

TEST(CalibrationFile, ShippedTargetsLoadAndBadFilesExitWithTwo) {
  const std::string shipped = rocklab::test::source_dir() + "/lab/calibrate/lac_du_bonnet_2d.json";
  const CalibrationFile c = load_calibration(shipped);
  EXPECT_EQ(c.targets.size(), 7u);
  EXPECT_EQ(c.params.size(), 8u);
  // Every shipped calibration file loads (its card, parameters and tests agree).
  for (const char* f : {"lac_du_bonnet.json", "lac_du_bonnet_slits.json", "berea.json",
                        "acceptance/lac_du_bonnet_2d_2x_off.json"})
    EXPECT_NO_THROW(load_calibration(rocklab::test::source_dir() + "/lab/calibrate/" + f)) << f;
  EXPECT_EQ(
      load_calibration(rocklab::test::source_dir() + "/lab/calibrate/berea.json").targets.size(),
      4u);
  std::string msg;
  EXPECT_EQ(rocklab::test::run_command(rocklab::test::binary() + " calibrate " + shipped + " -o " +
                                           (rocklab::test::scratch_root() / "chk").string() +
                                           " --check",
                                       &msg),
            0)
      << msg;
  EXPECT_NE(msg.find("parameter    flatjoint.fj_ten.sd/flatjoint.fj_ten"), std::string::npos)
      << msg;
  nlohmann::json bad = good_calibration();
  bad["parameters"]["flatjoint.fj_ten"]["bounds"] = {5e7, 5e7};
  const std::string file = write_calibration("bad_cli", bad);
  const std::string out = (rocklab::test::scratch_root() / "bad_cli_out").string();
  EXPECT_EQ(rocklab::test::run_command(
                rocklab::test::binary() + " calibrate " + file + " -o " + out, &msg),
            2);
  EXPECT_NE(msg.find("parameters.flatjoint.fj_ten"), std::string::npos) << msg;
  EXPECT_NE(msg.find("empty bounds"), std::string::npos) << msg;
  EXPECT_FALSE(std::filesystem::exists(out)) << "a bad file writes nothing";
}

// mpirun -np 2 shares each evaluation's replicate suites between two ranks and reaches the same
// card and convergence table as two local processes (--jobs 2). Where MPI is installed.
TEST(CalibrationCli, MpiRanksReachTheResultOfLocalJobs) {
#ifndef ROCKLAB_MPIEXEC
  GTEST_SKIP() << "built without MPI (libopenmpi-dev, openmpi-bin)";
#else
  namespace fs = std::filesystem;
  const fs::path dir = rocklab::test::scratch_root() / "calibrate_mpi";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const nlohmann::json j = tiny_calibration("tiny-mpi", {1, 2}, 2, 2, 0);
  const std::string file = (dir / "tiny.json").string();
  std::ofstream(file) << j.dump(2);
  const std::string bin = rocklab::test::binary() + " calibrate " + file + " -o ";
  std::string local, ranks;
  const int st_local =
      rocklab::test::run_command(bin + (dir / "jobs").string() + " --jobs 2", &local);
  // Root may run mpirun here (CI containers); one node's shared memory, cores or not.
  const std::string mpi =
      "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
      "OMPI_MCA_btl_vader_single_copy_mechanism=none " ROCKLAB_MPIEXEC " -np 2 --oversubscribe ";
  // A machine where mpirun cannot start two processes at all (no usable launcher) is not
  // where this can be tested; say so rather than fail.
  if (std::string probe; rocklab::test::run_command(mpi + "true", &probe) != 0)
    GTEST_SKIP() << "mpirun cannot start two processes here: " << probe;
  const int st_mpi = rocklab::test::run_command(mpi + bin + (dir / "mpi").string(), &ranks);
  ASSERT_TRUE(st_local == 0 || st_local == 1) << local;
  EXPECT_EQ(st_mpi, st_local) << ranks;
  // One summary, from rank 0 (mpirun adds its own lines about the exit status 1).
  EXPECT_EQ(std::regex_search(ranks, std::regex("calibration .*\n(.|\n)*calibration ")), false)
      << ranks;
  for (const char* f : {"card.json", "convergence.csv"})
    EXPECT_EQ(rocklab::test::read_file(dir / "mpi" / f), rocklab::test::read_file(dir / "jobs" / f))
        << f;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(ranks, m, std::regex(R"(\((\d+) suites run, (\d+) cached\))")))
      << ranks;
  EXPECT_GE(std::stoi(m[1]), 6) << "every evaluation runs two replicate suites";
#endif
}

TEST(CalibrationFile, OverridesSetTheCardAsACalibrationSetsItsParameters) {
  const nlohmann::json card = {{"porosity", 0.2},
                               {"flatjoint",
                                {{"fj_ten", {{"mean", 2e6}, {"sd", 4e5}}},
                                 {"types", {{"bonded", 0.9}, {"gapped", 0.0}, {"slit", 0.1}}}}}};
  const nlohmann::json out = rocklab::calibration::override_card(
      card,
      {{"flatjoint.fj_ten", 3e6},
       {"flatjoint.types.slit", 0.3},
       {"porosity", 0.25},
       {"specimen", {{"shape", "disk"}, {"diameter", 0.05}, {"thickness", 0.025}}}},
      "card.json");
  EXPECT_EQ(out["flatjoint"]["fj_ten"]["mean"], 3e6);
  EXPECT_DOUBLE_EQ(out["flatjoint"]["fj_ten"]["sd"].get<double>(), 6e5); // CoV 0.2 kept
  EXPECT_DOUBLE_EQ(out["flatjoint"]["types"]["bonded"].get<double>(), 0.7);
  EXPECT_EQ(out["porosity"], 0.25);
  EXPECT_EQ(out["specimen"]["shape"], "disk");
  EXPECT_EQ(card["porosity"], 0.2); // the input is untouched
  try {
    rocklab::calibration::override_card(card, {{"flatjoin.fj_ten", 1.0}}, "card.json");
    ADD_FAILURE() << "an override in a section the card lacks was accepted";
  } catch (const rocklab::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("card.json: override 'flatjoin.fj_ten'"),
              std::string::npos)
        << e.what();
  }
}
