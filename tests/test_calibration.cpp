// The calibration stages on a cheap synthetic rock with a known answer: every parameter starts 2x
// off, the measurements carry 0.5 % noise, and the targets must be met within the acceptance
// tolerances in at most 40 evaluations.
#include "lab/calibration/stages.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

using namespace rocklab::calibration;

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
  return m;
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
  std::vector<Param> params{{"emod", Role::Modulus, 1e9, 1e12, 1.2e11},
                            {"kratio", Role::StiffnessRatio, 1.0, 8.0, 5.0},
                            {"ten", Role::Strength, 1e6, 1e9, 4e7},
                            {"coh_over_ten", Role::Shape, 1.0, 20.0, 16.0},
                            {"slit", Role::Shape, 0.0, 0.5, 0.4}};
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
