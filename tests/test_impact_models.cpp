// Impact contact models of the rock-impact thesis: restitution of a ball on a rigid facet against
// the closed forms (hysteretic: sqrt(K_load / K_unload); elastic-perfectly-plastic power
// function: Eq. 30), energy balance, and stability at the automatic time step.
#include "helpers.hpp"

#include "contact/registry.hpp"

#include <cmath>

using namespace rocklab;
using rocklab::test::near_rel;

namespace {

struct Impact {
  double restitution = 0; ///< rebound speed / impact speed
  double balance_rel = 0; ///< |energy balance error| / initial kinetic energy
  double plastic = 0;     ///< dissipated by the contact [J]
  double kinetic0 = 0;    ///< [J]
  double max_force = 0;   ///< [N]
  long steps_in_contact = 0;
};

// A 3D ball (R = 0.04 m, 2600 kg/m3, the thesis' test particle) thrown at speed v onto a facet;
// no gravity, no damping; automatic time step (safety factor 0.08).
Impact impact(const ModelProps& props, double v, double safety = 0.08) {
  Model m;
  m.settings.dim = 3;
  m.settings.local_damping = 0;
  m.settings.gravity = Vec3::Zero();
  // An impact needs tens of cycles in contact (thesis section 5.1): a tenth of the quasi-static
  // step factor.
  m.settings.timestep_safety = safety;
  const double R = 0.04;
  m.walls.push_back(test::plane_wall(3, Vec3::Zero(), Vec3::UnitZ(), 1.0));
  const std::size_t b = m.balls.add(3, 1, Vec3(0, 0, R + 1e-4), R, 2600, m.group_index("rock"));
  m.balls.vel[b] = Vec3(0, 0, -v);
  ModelRule rule;
  rule.ball_facet = true;
  rule.props = props;
  m.rules.push_back(rule);
  m.initialize();
  Impact r;
  r.kinetic0 = 0.5 * m.balls.mass[b] * v * v;
  bool touched = false;
  for (long k = 0; k < 20'000'000; ++k) {
    m.cycle(1);
    const bool contact = !m.contacts().empty() && m.contacts()[0].gap < 0;
    if (contact) {
      touched = true;
      ++r.steps_in_contact;
      r.max_force = std::max(r.max_force, m.contact_outputs()[0].force.norm());
    } else if (touched) {
      break;
    }
  }
  r.restitution = m.balls.vel[b].z() / v;
  const EnergyLedger e = m.energy();
  r.plastic = e.plastic + e.dashpot;
  r.balance_rel = std::abs(e.balance_error()) / r.kinetic0;
  return r;
}

PowerPlasticProps power(double kn, double T, double b) {
  PowerPlasticProps p;
  p.pp_kn = kn;
  p.pp_ks = 0.15 * kn;
  p.pp_fric = 0.6;
  p.pp_T = T;
  p.pp_b = b;
  return p;
}

} // namespace

TEST(ImpactModels, PowerFunctionRestitutionMatchesEquation30) {
  // The thesis' Fig. 40 contact: K = 1e6 N/m, T = 4e3 N (elastic displacement e = 4 mm).
  const double kn = 1e6, T = 4e3;
  const double mass = 2600 * 4.0 / 3.0 * M_PI * std::pow(0.04, 3);
  for (double b : {1.0, 2.0, 5.0, 10.0, 30.0})
    for (double v : {2.0, 6.0, 10.0, 15.0}) {
      const Impact r = impact(power(kn, T, b), v);
      const double expect = powerplastic::restitution(mass, v, kn, T, b);
      EXPECT_TRUE(near_rel(r.restitution, expect, 0.01)) << "b " << b << " v " << v;
      EXPECT_LT(r.max_force, T * (1 + 1e-12)) << "the transition force caps the load";
      EXPECT_LT(r.balance_rel, 1e-3) << "b " << b << " v " << v;
      // The energy lost is what the restitution says.
      EXPECT_NEAR(r.plastic / r.kinetic0, 1 - r.restitution * r.restitution, 2e-3);
      EXPECT_GT(r.steps_in_contact, 20); // enough cycles per impact (thesis section 5.1)
    }
}

TEST(ImpactModels, TriangularLimitsAreOneAndRootHalf) {
  // b = 1: without plastic flow the unloading line is the loading line (restitution 1); when the
  // plastic displacement dominates (T tiny, g = e / p -> 0) Eq. 30 gives sqrt(0.5), the
  // triangular model's minimum of thesis section 5.1.
  EXPECT_TRUE(near_rel(impact(power(1e6, 1e12, 1.0), 5.0).restitution, 1.0, 1e-3));
  // T = 100 N at 2 m/s: p = 14 mm of plastic flow against e = 0.1 mm, g = 0.007.
  const Impact r = impact(power(1e6, 100.0, 1.0), 2.0);
  EXPECT_TRUE(near_rel(r.restitution, std::sqrt(0.5), 0.01));
  const double mass = 2600 * 4.0 / 3.0 * M_PI * std::pow(0.04, 3);
  EXPECT_TRUE(
      near_rel(r.restitution, powerplastic::restitution(mass, 2.0, 1e6, 100.0, 1.0), 0.005));
}

TEST(ImpactModels, HysteresisRestitutionIsRootOfStiffnessRatio) {
  for (double d : {0.1, 0.25, 0.5, 0.8, 1.0})
    for (double v : {1.0, 10.0}) {
      HystereticProps h;
      h.hys_knm = 6.4e7;
      h.hys_dampn = d;
      h.hys_ks = 9.6e6;
      h.hys_fric = 0.5;
      const Impact r = impact(h, v);
      EXPECT_TRUE(near_rel(r.restitution, std::sqrt(d), 0.01)) << "dampn " << d << " v " << v;
      EXPECT_LT(r.balance_rel, 1e-3);
    }
}

TEST(ImpactModels, StiffContactsStayStableAtTheAutomaticTimeStep) {
  // The thesis' blow-up case: a stiff contact (6.4e10 N/m) hit fast. The rebound may never be
  // faster than the impact.
  HystereticProps h;
  h.hys_knm = 6.4e10;
  h.hys_dampn = 0.3;
  for (double safety : {0.08, 0.8})
    for (double v : {1.0, 15.0}) {
      EXPECT_LE(impact(h, v, safety).restitution, 1.0);
      EXPECT_LE(impact(power(6.4e10, 4e3, 8.0), v, safety).restitution, 1.0);
      // the elastic-power model (no transition force) that blew up in the thesis
      EXPECT_LE(impact(power(6.4e10, 1e15, 2.0), v, safety).restitution, 1.0);
    }
}

namespace {

// Two bonded spheres (R = 1 cm) touching along z; the upper one is driven at velocity v (both
// fixed otherwise). Returns the largest tensile and shear force seen and the bond_break events.
struct BondRun {
  double max_tension = 0, max_shear = 0, force_after = -1;
  std::vector<Event> events;
};

BondRun drive_bonded_pair(const Vec3& v, double tenf, double shearf, double kn, double steps) {
  ContactBondProps p;
  p.linear.kn = kn;
  p.linear.ks = kn;
  p.linear.fric = 0.5;
  p.cb_tenf = tenf;
  p.cb_shearf = shearf;
  const double R = 0.01;
  const auto pair = test::driven_pair(Vec3::Zero(), Vec3(0, 0, 2 * R), R, v, p);
  Model& m = *pair;
  BondRun r;
  for (int k = 0; k < steps; ++k) {
    m.cycle(1);
    m.drain_events(r.events);
    if (m.contacts().empty())
      break;
    const ContactOutput& o = m.contact_outputs()[0];
    const Vec3 n = m.contacts()[0].n;
    const double fn = o.force.dot(n); // > 0: pulls ball 2 back towards ball 1 (tension)
    const double fs = (o.force - o.force.dot(n) * n).norm();
    r.max_tension = std::max(r.max_tension, -fn);
    r.max_shear = std::max(r.max_shear, fs);
    r.force_after = o.force.norm();
  }
  std::erase_if(r.events, [](const Event& e) { return e.type != EventType::BondBreak; });
  return r;
}

} // namespace

TEST(ContactBond, BreaksInTensionAtItsNormalStrength) {
  const double kn = 1e8, v = 0.01, tenf = 500;
  const BondRun r = drive_bonded_pair(Vec3(0, 0, v), tenf, 1e9, kn, 2000);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].mode, 1);
  // The tension grows by kn v dt per step and never reaches the strength while bonded.
  EXPECT_LT(std::abs(r.max_tension), tenf);
  EXPECT_GT(std::abs(r.max_tension), tenf - kn * v * 1e-6 * 1.01);
  EXPECT_EQ(r.force_after, 0.0); // no force once broken and open
}

TEST(ContactBond, BreaksInShearWithoutSlippingFirst) {
  const double kn = 1e8, v = 0.01, shearf = 300;
  const BondRun r = drive_bonded_pair(Vec3(v, 0, 0), 1e9, shearf, kn, 2000);
  ASSERT_EQ(r.events.size(), 1u);
  EXPECT_EQ(r.events[0].mode, 2);
  // Bonded: no Coulomb limit (zero normal force would allow no shear at all).
  EXPECT_GT(r.max_shear, shearf - kn * v * 1e-6 * 1.01);
  EXPECT_LT(r.max_shear, shearf);
}

TEST(ImpactModels, HystereticBondCarriesTensionUntilItsStrength) {
  // Two touching spheres pulled apart at a constant speed: bonded, the hysteretic contact pulls
  // back with K_unload until the tension reaches hys_tenf, then the bond breaks once; unbonded it
  // never carries tension.
  for (double tenf : {0.0, 500.0}) {
    Model m;
    m.settings.dim = 3;
    m.settings.local_damping = 0;
    m.settings.timestep = 1e-7;
    const double R = 0.01;
    const std::size_t a = m.balls.add(3, 1, Vec3(-R, 0, 0), R, 2600, 0);
    const std::size_t b = m.balls.add(3, 2, Vec3(R, 0, 0), R, 2600, 0);
    for (std::size_t i : {a, b})
      m.balls.fixity[i] = 0x3f;
    m.balls.vel[a] = Vec3(-0.1, 0, 0);
    m.balls.vel[b] = Vec3(0.1, 0, 0);
    HystereticProps h;
    h.hys_knm = 1e7;
    h.hys_dampn = 0.5;
    h.hys_ks = 5e6;
    h.hys_tenf = tenf;
    h.hys_shearf = 2 * tenf;
    ModelRule r;
    r.props = h;
    m.rules.push_back(r);
    m.initialize();
    ASSERT_EQ(m.contacts().size(), 1u);
    double max_tension = 0;
    std::int64_t breaks = 0;
    std::vector<Event> ev;
    for (int k = 0; k < 3000; ++k) {
      m.cycle(1);
      ev.clear();
      m.drain_events(ev);
      for (const Event& e : ev)
        breaks += e.type == EventType::BondBreak;
      for (std::size_t ci = 0; ci < m.contacts().size(); ++ci)
        max_tension =
            std::max(max_tension, local_components(m.contacts()[ci], m.contact_outputs()[ci]).Fn);
    }
    if (tenf == 0) {
      EXPECT_EQ(max_tension, 0.0);
      EXPECT_EQ(breaks, 0);
    } else {
      // K_unload = 2 k / (1 + d) = 1.333e7 N/m; 2e-8 m of opening per step: 0.27 N per step
      EXPECT_GT(max_tension, tenf - 0.5);
      EXPECT_LT(max_tension, tenf + 0.5);
      EXPECT_EQ(breaks, 1);
      EXPECT_GT(m.energy().bond_break, 0);
    }
  }
}
