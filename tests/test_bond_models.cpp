// Bonded contact models driven directly with prescribed relative motion: breakage thresholds,
// partial damage, the smooth joint on an inclined plane, and energy checks.
#include "helpers.hpp"

#include <numbers>

using namespace rocklab;
using rocklab::test::near_rel;

namespace {

constexpr double kPi = std::numbers::pi;

/// One contact fed with relative-motion increments in contact-plane coordinates (3D: n = z,
/// s = x, t = y; 2D: n = x, s = -z, t = y). Tracks the work done on the contact (trapezoid).
struct Driver {
  ModelBatches b;
  ModelKind kind;
  std::uint32_t slot = 0;
  ContactKinematics k;
  ContactResult out;
  EventBuffer events;
  double work = 0;

  Driver(const ModelProps& p, int dim, double R = 6.25e-3, double gap0 = 0) {
    CreationInfo ci;
    ci.dim = dim;
    ci.R1 = ci.R2 = R;
    ci.gap = gap0;
    k.dim = dim;
    k.dt = 1e-6;
    k.R1 = k.R2 = R;
    k.mass_eff = 1.0;
    k.gap = gap0;
    if (dim == 3) {
      k.n = Vec3::UnitZ();
      k.s = Vec3::UnitX();
      k.t = Vec3::UnitY();
    } else {
      k.n = Vec3::UnitX();
      k.s = -Vec3::UnitZ();
      k.t = Vec3::UnitY();
    }
    ci.n = k.n;
    kind = kind_of(p);
    slot = create_contact_data(b, p, ci);
  }
  void step(double dn, double dss = 0, double dst = 0, double dtt = 0, double dtbs = 0,
            double dtbt = 0) {
    const ContactResult before = out;
    k.gap += dn;
    k.d_dn = dn;
    k.d_dss = dss;
    k.d_dst = dst;
    k.d_tt = dtt;
    k.d_tbs = dtbs;
    k.d_tbt = dtbt;
    EventSink sink{&events, 0, 0};
    update_contact(b, kind, slot, k, out, sink);
    // Work on the contact: minus the mean force (on piece 2) times the relative increment.
    auto dot = [&](const ContactResult& r) {
      return -r.Fn * dn + r.Fss * dss + r.Fst * dst + r.Mt * dtt + r.Mbs * dtbs + r.Mbt * dtbt;
    };
    work -= 0.5 * (dot(before) + dot(out));
  }
  ContactEnergy energy() const { return contact_energy(b, kind, slot); }
  int breaks(int mode = 0) const {
    int n = 0;
    for (const Event& e : events)
      n += e.type == EventType::BondBreak && (mode == 0 || e.mode == mode);
    return n;
  }
  double shear() const { return std::hypot(out.Fss, out.Fst); }
};

FlatJointProps fj_props(int Nr, int Nal, double ten, double coh, double fa = 0, double fric = 0) {
  FlatJointProps p;
  p.fj_Nr = Nr;
  p.fj_Nal = Nal;
  p.fj_rmul = 0.8;
  p.fj_kn = 2e12;
  p.fj_ks = 1e12;
  p.fj_ten = ten;
  p.fj_coh = coh;
  p.fj_fa = fa;
  p.fj_fric = fric;
  p.bond = true;
  return p;
}

double joint_area(int dim, double R) {
  return dim == 2 ? 2 * R : kPi * R * R;
}

} // namespace

TEST(FlatJointBreakage, PureTensionBreaksEveryElementAtSigmaCTimesArea) {
  for (int dim : {2, 3}) {
    for (bool exact : {false, true}) {
      if (dim == 2 && exact)
        continue;
      FlatJointProps p = fj_props(dim == 2 ? 4 : 2, 8, 1e6, 1e20);
      p.fj_exact = exact;
      Driver d(p, dim);
      const double A = joint_area(dim, 5e-3), dn = 1e-10;
      double peak = 0;
      int steps = 0;
      while (d.breaks() == 0 && steps < 100000) {
        d.step(dn);
        peak = std::max(peak, d.out.Fn);
        ++steps;
      }
      const int n_elem = dim == 2 ? 4 : 16;
      EXPECT_EQ(d.breaks(1), n_elem) << dim << "D: every element breaks, in tension, at once";
      EXPECT_LE(peak, 1e6 * A * (1 + 1e-12));
      EXPECT_GE(peak, 1e6 * A - 2e12 * A * dn * 1.0001);
      EXPECT_EQ(d.out.Fn, 0.0);
      d.step(dn);
      EXPECT_EQ(d.out.Fn, 0.0); // unbonded and open: no tension
    }
  }
}

TEST(FlatJointBreakage, PureShearBreaksAtCohesionMinusSigmaTanPhi) {
  for (int dim : {2, 3}) {
    const double phi = 30, c = 5e6, sigma0 = -2e6, mu = 0.4;
    Driver d(fj_props(dim == 2 ? 4 : 2, 8, 1e20, c, phi, mu), dim);
    const double A = joint_area(dim, 5e-3);
    d.step(sigma0 / 2e12); // uniform compression sigma0
    EXPECT_TRUE(near_rel(d.out.Fn, sigma0 * A, 1e-12));
    const double dst = 1e-10;
    double peak = 0, stored = 0, work0 = 0;
    for (int i = 0; i < 100000 && d.breaks() == 0; ++i) {
      stored = d.energy().strain;
      work0 = d.work;
      d.step(0, 0, dst);
      peak = std::max(peak, d.shear());
    }
    const double tau_c = c - sigma0 * std::tan(phi * kPi / 180);
    EXPECT_EQ(d.breaks(2), dim == 2 ? 4 : 16);
    // Energy: the breaks release the shear part; the compressed, now unbonded elements keep
    // their normal strain energy (booking it too left a crushed Brazilian disk's ledger 5 % open).
    double released = 0;
    for (const Event& e : d.events)
      released += e.type == EventType::BondBreak ? e.energy : 0.0;
    const double shear_part = 0.5 * std::pow(tau_c * A, 2) / (1e12 * A); // (tau_c A)^2 / 2 ks A
    EXPECT_TRUE(near_rel(released, shear_part, 1e-3)) << released << " vs " << shear_part;
    const double balance = stored + (d.work - work0) - d.energy().strain - released;
    EXPECT_LT(std::abs(balance), 1e-3 * stored)
        << "before " << stored << " after " << d.energy().strain << " released " << released;
    EXPECT_LE(peak, tau_c * A * (1 + 1e-12));
    EXPECT_GE(peak, tau_c * A - 1e12 * A * dst * 1.0001);
    // Broken and still compressed: friction holds mu |sigma| A.
    for (int i = 0; i < 200; ++i)
      d.step(0, 0, 1e-8);
    EXPECT_TRUE(near_rel(d.shear(), -mu * sigma0 * A, 1e-9));
    EXPECT_TRUE(near_rel(d.out.Fn, sigma0 * A, 1e-9));
  }
}

TEST(FlatJointBreakage, PartiallyBrokenJointCarriesOnlyCompressionAndFrictionWhereBroken) {
  const double mu = 0.5;
  Driver d(fj_props(4, 1, 1e6, 1e20, 0, mu), 2);
  // Bend until the two elements on the tension side have broken.
  while (d.breaks() < 2)
    d.step(0, 0, 0, 0, 1e-7);
  const auto els = d.b.of<FlatJoint>().pool.of(d.b.of<FlatJoint>().contacts[0]);
  int broken = 0;
  for (const auto& e : els)
    broken += e.B != BondState::Bonded;
  EXPECT_EQ(broken, 2);
  EXPECT_EQ(els[0].B, BondState::Tension); // element 1 sits at t = +0.75 R, the most stretched
  // Now close and shear the joint.
  for (int i = 0; i < 200; ++i)
    d.step(-2e-9, 0, 2e-8);
  bool some_slip = false;
  for (const auto& e : els) {
    if (e.B == BondState::Bonded)
      continue;
    EXPECT_LE(e.Fn, 0.0);
    EXPECT_LE(std::hypot(e.Fss, e.Fst), mu * std::abs(e.Fn) * (1 + 1e-12));
    some_slip = some_slip || e.slip;
  }
  EXPECT_TRUE(some_slip);
  // Opening again: the broken elements carry no tension.
  for (int i = 0; i < 400; ++i)
    d.step(1e-8);
  for (const auto& e : els) {
    if (e.B != BondState::Bonded) {
      EXPECT_LE(e.Fn, 0.0);
    }
  }
}

namespace {
LinearPBondProps pb_props(double mcf, double ten, double coh, double fa = 0) {
  LinearPBondProps p;
  p.linear.kn = 0;
  p.pb_rmul = 0.8;
  p.pb_kn = 2e12;
  p.pb_ks = 1e12;
  p.pb_mcf = mcf;
  p.pb_ten = ten;
  p.pb_coh = coh;
  p.pb_fa = fa;
  p.bond = true;
  return p;
}
} // namespace

TEST(ParallelBondBreakage, TensionBendingAndShear) {
  for (int dim : {2, 3}) {
    const double R = 5e-3, A = joint_area(dim, R);
    const double I = dim == 2 ? 2.0 / 3.0 * R * R * R : 0.25 * kPi * std::pow(R, 4);
    for (double beta : {0.0, 1.0}) {
      // Pure tension breaks at sigma_c A whatever beta.
      Driver t(pb_props(beta, 1e6, 1e20), dim);
      double peak = 0;
      while (t.breaks() == 0) {
        t.step(1e-10);
        peak = std::max(peak, t.out.Fn);
      }
      EXPECT_EQ(t.breaks(1), 1);
      EXPECT_LE(peak, 1e6 * A * (1 + 1e-12));
      EXPECT_GE(peak, 1e6 * A - 2e12 * A * 1e-10 * 1.0001);
      EXPECT_EQ(t.out.Fn, 0.0);
      // Pure bending: with beta = 1 the bond breaks at |M| = sigma_c I / R; with beta = 0 the
      // moment does not load the bond periphery.
      Driver b(pb_props(beta, 1e6, 1e20), dim);
      double mpeak = 0;
      for (int i = 0; i < 20000 && b.breaks() == 0; ++i) {
        b.step(0, 0, 0, 0, 1e-7);
        mpeak = std::max(mpeak, std::abs(b.out.Mbs));
      }
      if (beta == 1.0) {
        EXPECT_EQ(b.breaks(1), 1);
        EXPECT_LE(mpeak, 1e6 * I / R * (1 + 1e-12));
        EXPECT_GE(mpeak, 1e6 * I / R - 2e12 * I * 1e-7 * 1.0001);
      } else {
        EXPECT_EQ(b.breaks(), 0);
      }
    }
    // Shear under compression: tau_c = c - sigma tan(phi), sigma = Fn / A.
    Driver s(pb_props(1.0, 1e20, 5e6, 30), dim);
    s.step(-1e-6); // sigma = -2e6 Pa
    const double sigma = s.out.Fn / A;
    EXPECT_TRUE(near_rel(sigma, -2e6, 1e-12));
    double peak = 0;
    for (int i = 0; i < 100000 && s.breaks() == 0; ++i) {
      s.step(0, 0, 1e-10);
      peak = std::max(peak, s.shear());
    }
    const double tau_c = 5e6 - sigma * std::tan(30 * kPi / 180);
    EXPECT_EQ(s.breaks(2), 1);
    EXPECT_LE(peak, tau_c * A * (1 + 1e-12));
    EXPECT_GE(peak, tau_c * A - 1e12 * A * 1e-10 * 1.0001);
  }
}

namespace {
SmoothJointProps sj_props(double dip, double mu, double psi) {
  SmoothJointProps p;
  p.sj_kn = 1e12;
  p.sj_ks = 1e12;
  p.sj_fric = mu;
  p.sj_da = psi;
  p.dip = dip;
  p.ddir = 90; // n_j = (sin dip, 0, cos dip)
  return p;
}
} // namespace

TEST(SmoothJoint, SlidesAtTheCoulombLimitWithDilation) {
  const double dip = 30, mu = 0.3, psi = 10, delta = 1e-9;
  const double th = dip * kPi / 180;
  Driver plain(sj_props(dip, mu, 0), 3), dil(sj_props(dip, mu, psi), 3);
  const double A = kPi * std::pow(6.25e-3, 2);
  // Piece 2 pushed straight down (along -n_c): closing delta cos(dip), sliding delta sin(dip).
  plain.step(-delta);
  dil.step(-delta);
  const double kn = 1e12 * A, ks = 1e12 * A;
  const double trial = ks * delta * std::sin(th), limit = mu * kn * delta * std::cos(th);
  ASSERT_GT(trial, limit); // tan 30 > 0.3: the joint slides
  const auto& sj = dil.b.of<SmoothJoint>().contacts[0];
  EXPECT_TRUE(sj.slip);
  EXPECT_TRUE(near_rel(sj.Fs.norm(), limit, 1e-12));
  // Dilation: the compressive normal force grows by (|Fs*| - Fs^mu) / ks * kn tan(psi).
  const double growth = plain.b.of<SmoothJoint>().contacts[0].Fn - sj.Fn;
  EXPECT_TRUE(near_rel(growth, (trial - limit) / ks * kn * std::tan(psi * kPi / 180), 1e-12));
  // The force lies along the joint, not the contact normal.
  EXPECT_NE(dil.out.Fss, 0.0);
}

TEST(SmoothJoint, HoldsBelowTheCoulombLimit) {
  Driver d(sj_props(15, 0.5, 10), 3); // tan 15 = 0.27 < 0.5
  for (int i = 0; i < 100; ++i)
    d.step(-1e-9);
  const auto& sj = d.b.of<SmoothJoint>().contacts[0];
  EXPECT_FALSE(sj.slip);
  EXPECT_TRUE(near_rel(sj.Fs.norm() / -sj.Fn, std::tan(15 * kPi / 180), 1e-9));
  EXPECT_EQ(d.energy().slip, 0.0);
}

TEST(SmoothJoint, BondedJointHoldsUntilItBreaksThenSlides) {
  SmoothJointProps p = sj_props(30, 0.3, 0);
  p.sj_coh = 2e6;
  p.sj_ten = 1e7;
  p.bond = true;
  Driver d(p, 3);
  EXPECT_EQ(d.b.of<SmoothJoint>().contacts[0].state, BondState::Bonded);
  const double A = kPi * std::pow(6.25e-3, 2);
  int steps = 0;
  while (d.breaks() == 0 && steps < 100000) {
    d.step(-1e-10);
    ++steps;
    if (d.breaks() == 0) {
      EXPECT_FALSE(d.b.of<SmoothJoint>().contacts[0].slip);
    }
  }
  EXPECT_EQ(d.breaks(2), 1);
  const auto& sj = d.b.of<SmoothJoint>().contacts[0];
  const double tau_c = 2e6; // phi = 0
  // Broken in shear under compression: the shear force is limited by friction.
  EXPECT_TRUE(near_rel(sj.Fs.norm(), -0.3 * sj.Fn, 1e-12));
  EXPECT_GT(tau_c * A, 0.0);
  d.step(-1e-10);
  EXPECT_TRUE(d.b.of<SmoothJoint>().contacts[0].slip);
}

TEST(SmoothJoint, ResistsNoRelativeRotation) {
  Driver d(sj_props(30, 0.6, 0), 3);
  d.step(-1e-8);
  const ContactResult before = d.out;
  d.step(0, 0, 0, 1e-3, 2e-3, -3e-3);
  EXPECT_EQ(d.out.Mt, 0.0);
  EXPECT_EQ(d.out.Mbs, 0.0);
  EXPECT_EQ(d.out.Mbt, 0.0);
  EXPECT_EQ(d.out.Fn, before.Fn);
  EXPECT_EQ(d.out.Fss, before.Fss);
}

namespace {
// Load along a fixed random path, then retrace it exactly: elastic work = stored energy.
void elastic_round_trip(Driver& d, bool rotations, double scale, const char* what) {
  struct Inc {
    double v[6];
  };
  std::vector<Inc> path;
  std::uint64_t x = 12345;
  auto rnd = [&]() {
    x = x * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(x >> 11) * 0x1.0p-53 - 0.5;
  };
  for (int i = 0; i < 300; ++i) {
    Inc inc{{-0.2 * scale + scale * rnd(), scale * rnd(), scale * rnd(),
             rotations ? 100 * scale * rnd() : 0.0, rotations ? 100 * scale * rnd() : 0.0,
             rotations ? 100 * scale * rnd() : 0.0}};
    if (d.k.dim == 2)
      inc.v[1] = inc.v[3] = inc.v[5] = 0;
    path.push_back(inc);
  }
  for (const Inc& i : path)
    d.step(i.v[0], i.v[1], i.v[2], i.v[3], i.v[4], i.v[5]);
  const ContactEnergy e = d.energy();
  const double stored = e.strain + e.bond_strain;
  EXPECT_GT(stored, 0.0) << what;
  EXPECT_TRUE(near_rel(d.work, stored, 1e-9)) << what;
  EXPECT_EQ(d.breaks(), 0) << what;
  for (auto it = path.rbegin(); it != path.rend(); ++it)
    d.step(-it->v[0], -it->v[1], -it->v[2], -it->v[3], -it->v[4], -it->v[5]);
  const ContactEnergy e2 = d.energy();
  EXPECT_NEAR(e2.strain + e2.bond_strain, 0.0, 1e-9 * stored) << what;
  EXPECT_NEAR(d.work, 0.0, 1e-9 * stored) << what;
}
} // namespace

TEST(ContactEnergy, StrainEnergyEqualsElasticWork) {
  for (int dim : {2, 3}) {
    Driver pb(pb_props(1.0, 1e20, 1e20), dim);
    elastic_round_trip(pb, true, 1e-9, "linearpbond");
    Driver fj(fj_props(dim == 2 ? 4 : 2, 8, 1e20, 1e20), dim);
    elastic_round_trip(fj, true, 1e-9, "flatjoint");
    if (dim == 3) {
      FlatJointProps p = fj_props(3, 16, 1e20, 1e20);
      p.fj_exact = true;
      Driver fe(p, dim);
      elastic_round_trip(fe, true, 1e-9, "flatjoint exact");
      SmoothJointProps sp = sj_props(30, 0.5, 0);
      sp.sj_coh = sp.sj_ten = 1e20;
      sp.bond = true;
      Driver sj(sp, dim);
      elastic_round_trip(sj, false, 1e-9, "smoothjoint");
    }
  }
}

TEST(ContactEnergy, SlipEnergyEqualsFrictionWork) {
  // Unbonded, compressed, then sheared far beyond the elastic range: the work done equals the
  // stored strain energy plus the slip energy.
  FlatJointProps fp = fj_props(2, 8, 0, 0, 0, 0.6);
  fp.bond = false;
  Driver fj(fp, 3);
  SmoothJointProps sp = sj_props(0, 0.6, 0); // joint normal along the contact normal
  Driver sj(sp, 3);
  LinearPBondProps pp = pb_props(1, 0, 0);
  pp.bond = false;
  pp.linear.kn = 1e8;
  pp.linear.ks = 5e7;
  pp.linear.fric = 0.6;
  Driver lin(pp, 3);
  // The driver's trapezoid work is approximate only in the one step where slip begins (the
  // true path is an elastic ramp, then slip at the limit), so the increments are kept small.
  for (Driver* d : {&fj, &sj, &lin}) {
    d->step(-1e-7);
    for (int i = 0; i < 20000; ++i)
      d->step(0, 1e-10, 2e-10);
    const ContactEnergy e = d->energy();
    EXPECT_GT(e.slip, 10 * e.strain);
    EXPECT_TRUE(near_rel(d->work, e.strain + e.slip, 1e-6)) << static_cast<int>(d->kind);
  }
}

namespace {
struct Slide {
  double along;  // displacement of the block along the joint's down-dip direction [m]
  double across; // displacement normal to the joint [m]
  std::int64_t breaks;
};
Slide slide(const std::string& name, const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  Scene s = load_scene(test::source_dir() + "/examples/verification/" + name + ".json");
  test::transform_model(*s.model, R, Vec3::Zero());
  // The joint plane turns with the scene.
  auto& sj = std::get<SmoothJointProps>(s.model->rules[0].props);
  const Vec3 nj = R * smoothjoint::joint_normal(3, sj.dip, sj.ddir);
  sj.use_normal = true;
  sj.normal = nj;
  Model& m = *s.model;
  m.initialize();
  const Vec3 x0 = m.balls.pos[1];
  m.cycle(s.stages[0].run.cycles);
  std::vector<Event> ev;
  m.drain_events(ev);
  std::int64_t breaks = 0;
  for (const Event& e : ev)
    breaks += e.type == EventType::BondBreak;
  const Vec3 g = m.settings.gravity.normalized();
  const Vec3 down = (g - g.dot(nj) * nj).normalized();
  const Vec3 dx = m.balls.pos[1] - x0;
  return {dx.dot(down), dx.dot(nj), breaks};
}
} // namespace

TEST(SmoothJoint, BlockOnAnInclinedJointSlidesAtTheCoulombLimit) {
  const double th = kPi / 6, T = 0.1; // dip 30 degrees, 50000 steps of 2 us
  const double a = 9.81 * (std::sin(th) - 0.3 * std::cos(th));
  const Slide s = slide("smooth_joint_slide");
  EXPECT_TRUE(near_rel(s.along, 0.5 * a * T * T, 2e-3));
  EXPECT_LT(std::abs(s.across), 1e-5);
  // Holding: only the elastic shear displacement, at most twice the static m g sin / (ks A).
  const double m = 2650 * 4.0 / 3 * kPi * std::pow(6.25e-3, 3);
  const double elastic = 2 * m * 9.81 * std::sin(th) / (1e9 * kPi * std::pow(6.25e-3, 2));
  const Slide h = slide("smooth_joint_hold"); // mu = 0.7 > tan 30
  EXPECT_LT(std::abs(h.along), elastic);
  const Slide b = slide("smooth_joint_bonded_strong");
  EXPECT_LT(std::abs(b.along), elastic);
  EXPECT_EQ(b.breaks, 0);
  const Slide w = slide("smooth_joint_bonded_weak"); // breaks in shear at once, then slides
  EXPECT_EQ(w.breaks, 1);
  EXPECT_TRUE(near_rel(w.along, 0.5 * a * T * T, 5e-3));
  // Rotated arbitrarily in 3D (with gravity and the joint plane): the same motion.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(2.3, Vec3(-0.4, 0.7, 0.2).normalized()).toRotationMatrix();
  const Slide r = slide("smooth_joint_slide", R);
  EXPECT_TRUE(near_rel(r.along, s.along, 1e-9));
  const Slide rw = slide("smooth_joint_bonded_weak", R);
  EXPECT_EQ(rw.breaks, 1);
  EXPECT_TRUE(near_rel(rw.along, w.along, 1e-9));
}

TEST(SmoothJoint, InheritsSurfacePropertiesInSeries) {
  const std::filesystem::path file = rocklab::test::scratch_root() / "rocklab-inherit.json";
  std::ofstream(file) << R"({
    "dimension": 3,
    "balls": [{"id": 1, "position": [0, 0, 0], "radius": 0.005, "density": 2650, "group": "a"},
              {"id": 2, "position": [0, 0, 0.0099], "radius": 0.005, "density": 2650, "group": "b"},
              {"id": 3, "position": [0.0099, 0, 0], "radius": 0.005, "density": 2650, "group": "a"}],
    "surface": [{"group": "a", "sj_kn": 2e12, "sj_ks": 1e12, "sj_fric": 0.4, "kn": 1e6, "fric": 0.2},
                {"group": "b", "sj_kn": 2e12, "sj_ks": 3e12, "sj_fric": 0.6, "kn": 3e6, "fric": 0.7}],
    "contact_models": [
      {"between": "ball-ball", "groups": ["a", "b"], "model": "smoothjoint",
       "properties": {"inherit": true, "sj_kn": 1, "dip": 10}},
      {"between": "ball-ball", "groups": ["a", "a"], "model": "linear",
       "properties": {"inherit": true, "kn": 5}}],
    "run": {"cycles": 1}})";
  Scene s = load_scene(file.string());
  s.model->initialize();
  const ModelBatches& b = s.model->batches();
  ASSERT_EQ(b.of<SmoothJoint>().contacts.size(), 1u);                     // balls 1 (a) and 2 (b)
  EXPECT_TRUE(near_rel(b.of<SmoothJoint>().contacts[0].kn, 1e12, 1e-15)); // 2e12 and 2e12 in series
  EXPECT_TRUE(
      near_rel(b.of<SmoothJoint>().contacts[0].ks, 0.75e12, 1e-15)); // 1e12 and 3e12 in series
  EXPECT_EQ(b.of<SmoothJoint>().contacts[0].fric, 0.4);
  ASSERT_EQ(b.of<Linear>().contacts.size(), 1u); // balls 1 and 3 (a, a)
  EXPECT_TRUE(near_rel(b.of<Linear>().contacts[0].p.kn, 0.5e6, 1e-15));
  EXPECT_EQ(b.of<Linear>().contacts[0].p.fric, 0.2);
  EXPECT_EQ(b.of<Linear>().contacts[0].p.ks, 0.0); // not held by the groups: the rule value stays
}
