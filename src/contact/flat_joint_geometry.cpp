// Flat-joint interface geometry (flat-joint-contact-model.md, Eq. 13, 16-17): the unit-radius
// elements of each discretisation (2D segments, 3D annular sectors), built once and shared, and
// the exact moments of the compressed part of a sector (the exact-3D option,
// docs/flatjoint-exact-3d.md).
#include "contact/flat_joint.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>

namespace rocklab {

namespace {
constexpr double kPi = std::numbers::pi;

FlatJointGeometry build_geometry(int dim, int Nr, int Nal) {
  FlatJointGeometry g;
  g.dim = dim;
  g.Nr = Nr;
  g.Nal = dim == 2 ? 1 : Nal;
  const int n = Nr * g.Nal;
  g.A.resize(n);
  g.s.resize(n);
  g.t.resize(n);
  if (dim == 2) {
    for (int e = 1; e <= Nr; ++e) { // Eq. 13 (R = 1, unit thickness)
      g.A[e - 1] = 2.0 / Nr;
      g.s[e - 1] = 0.0;
      g.t[e - 1] = (-2.0 * e + 1 + Nr) / Nr;
    }
    return g;
  }
  g.r1.resize(n);
  g.r2.resize(n);
  g.a1.resize(n);
  g.a2.resize(n);
  g.Ixx.resize(n);
  g.Ixy.resize(n);
  g.Iyy.resize(n);
  g.Jp.resize(n);
  const double dr = 1.0 / Nr, da = 2 * kPi / Nal;
  for (int e = 1; e <= n; ++e) { // Eq. 16-17
    const int I = (e - 1) / Nal, J = e - 1 - I * Nal;
    const double r1 = I * dr, r2 = (I + 1) * dr, a1 = J * da, a2 = (J + 1) * da;
    const double A = 0.5 * (a2 - a1) * (r2 * r2 - r1 * r1);
    const double rr = (r2 * r2 * r2 - r1 * r1 * r1) / (r2 * r2 - r1 * r1);
    const int i = e - 1;
    g.r1[i] = r1;
    g.r2[i] = r2;
    g.a1[i] = a1;
    g.a2[i] = a2;
    g.A[i] = A;
    g.s[i] = 2.0 / 3.0 * (std::sin(a2) - std::sin(a1)) / (a2 - a1) * rr;
    g.t[i] = 2.0 / 3.0 * (std::cos(a1) - std::cos(a2)) / (a2 - a1) * rr;
    // Second moments about the interface centre: int s^2, int s t, int t^2 over the sector.
    const double r4 = (std::pow(r2, 4) - std::pow(r1, 4)) / 4;
    g.Ixx[i] = r4 * ((a2 - a1) / 2 + (std::sin(2 * a2) - std::sin(2 * a1)) / 4);
    g.Iyy[i] = r4 * ((a2 - a1) / 2 - (std::sin(2 * a2) - std::sin(2 * a1)) / 4);
    g.Ixy[i] = r4 * (std::cos(2 * a1) - std::cos(2 * a2)) / 4;
    g.Jp[i] = g.Ixx[i] + g.Iyy[i];
  }
  return g;
}

using Moments = flatjoint::Moments;

// Green's theorem: int int f dA = closed-line integral of F dt with dF/ds = f, for
// F = s, s^2/2, s t, s^3/3, s^2 t/2, s t^2. Straight segment, exact with 2-point Gauss (cubic).
void add_segment(double s0, double t0, double s1, double t1, Moments& m) {
  const double ds = s1 - s0, dt = t1 - t0;
  if (dt == 0)
    return;
  const double g = 0.5 / std::sqrt(3.0);
  for (double u : {0.5 - g, 0.5 + g}) {
    const double s = s0 + u * ds, t = t0 + u * dt, w = 0.5 * dt;
    m[0] += w * s;
    m[1] += w * s * s / 2;
    m[2] += w * s * t;
    m[3] += w * s * s * s / 3;
    m[4] += w * s * s * t / 2;
    m[5] += w * s * t * t;
  }
}

// Arc of radius rho from angle a to b (either direction), analytic antiderivatives.
void add_arc(double rho, double a, double b, Moments& m) {
  auto P = [](double x) {
    const double c = std::cos(x), s = std::sin(x);
    return std::array<double, 6>{x / 2 + std::sin(2 * x) / 4, // cos^2
                                 s - s * s * s / 3,           // cos^3
                                 -c * c * c / 3,              // cos^2 sin
                                 3 * x / 8 + std::sin(2 * x) / 4 + std::sin(4 * x) / 32, // cos^4
                                 -c * c * c * c / 4,            // cos^3 sin
                                 x / 8 - std::sin(4 * x) / 32}; // cos^2 sin^2
  };
  const auto pa = P(a), pb = P(b);
  const double r2 = rho * rho, r3 = r2 * rho, r4 = r3 * rho;
  m[0] += r2 * (pb[0] - pa[0]);
  m[1] += r3 / 2 * (pb[1] - pa[1]);
  m[2] += r3 * (pb[2] - pa[2]);
  m[3] += r4 / 3 * (pb[3] - pa[3]);
  m[4] += r4 / 2 * (pb[4] - pa[4]);
  m[5] += r4 * (pb[5] - pa[5]);
}

} // namespace

// Moments of {p in sector : gs + p . b < 0} (the compressed part of an unbonded element).
flatjoint::Moments flatjoint::clipped_moments(double r1, double r2, double a1, double a2, double gs,
                                              double bs, double bt) {
  Moments m{};
  const double bn = std::hypot(bs, bt);
  if (bn == 0) {
    if (gs < 0) {
      add_arc(r2, a1, a2, m);
      add_arc(r1, a2, a1, m);
      add_segment(r2 * std::cos(a2), r2 * std::sin(a2), r1 * std::cos(a2), r1 * std::sin(a2), m);
      add_segment(r1 * std::cos(a1), r1 * std::sin(a1), r2 * std::cos(a1), r2 * std::sin(a1), m);
    }
    return m;
  }
  const double beta = std::atan2(bt, bs);
  // Arc pieces with g < 0: cos(alpha - beta) < q, q = -gs / (rho |b|).
  auto clipped_arc = [&](double rho, double from, double to) {
    if (rho <= 0)
      return;
    const double lo = std::min(from, to), hi = std::max(from, to);
    const double q = -gs / (rho * bn);
    std::vector<std::pair<double, double>> pieces;
    if (q > 1) {
      pieces.emplace_back(lo, hi);
    } else if (q > -1) {
      const double phi = std::acos(q);
      for (int k = -1; k <= 1; ++k) {
        const double x0 = std::max(lo, beta + phi + 2 * kPi * k);
        const double x1 = std::min(hi, beta + 2 * kPi - phi + 2 * kPi * k);
        if (x1 > x0)
          pieces.emplace_back(x0, x1);
      }
    }
    for (auto [x0, x1] : pieces)
      if (to > from)
        add_arc(rho, x0, x1, m);
      else
        add_arc(rho, x1, x0, m);
  };
  // Radial pieces with g < 0 at angle alpha, traversed from r_from to r_to.
  auto clipped_radial = [&](double alpha, double r_from, double r_to) {
    const double c = std::cos(alpha), s = std::sin(alpha);
    const double slope = bs * c + bt * s; // g(r) = gs + r slope
    double lo = std::min(r_from, r_to), hi = std::max(r_from, r_to);
    if (slope > 0)
      hi = std::min(hi, -gs / slope);
    else if (slope < 0)
      lo = std::max(lo, -gs / slope);
    else if (gs >= 0)
      return;
    if (hi <= lo)
      return;
    if (r_to > r_from)
      add_segment(lo * c, lo * s, hi * c, hi * s, m);
    else
      add_segment(hi * c, hi * s, lo * c, lo * s, m);
  };
  clipped_arc(r2, a1, a2);
  clipped_radial(a2, r2, r1);
  clipped_arc(r1, a2, a1);
  clipped_radial(a1, r1, r2);
  // The zero-gap line inside the sector, traversed with the compressed side on its left.
  const double ns = bs / bn, nt = bt / bn;
  const double p0s = -gs * ns / bn, p0t = -gs * nt / bn; // closest point to the centre
  const double ds = -nt, dt = ns;
  const double d0 = std::hypot(p0s, p0t);
  if (d0 >= r2)
    return m;
  double u_lo = -std::sqrt(r2 * r2 - d0 * d0), u_hi = -u_lo;
  // Wedge a1 <= alpha <= a2 (convex: a2 - a1 < pi): cross(e1, p) >= 0 and cross(p, e2) >= 0.
  auto half_plane = [&](double ks, double kt) { // k . p(u) >= 0, p(u) = p0 + u d
    const double c0 = ks * p0s + kt * p0t, c1 = ks * ds + kt * dt;
    if (c1 > 0)
      u_lo = std::max(u_lo, -c0 / c1);
    else if (c1 < 0)
      u_hi = std::min(u_hi, -c0 / c1);
    else if (c0 < 0)
      u_hi = u_lo - 1;
  };
  half_plane(-std::sin(a1), std::cos(a1));
  half_plane(std::sin(a2), -std::cos(a2));
  auto chord = [&](double u0, double u1) {
    if (u1 > u0)
      add_segment(p0s + u0 * ds, p0t + u0 * dt, p0s + u1 * ds, p0t + u1 * dt, m);
  };
  if (d0 < r1 && r1 > 0) {
    const double h = std::sqrt(r1 * r1 - d0 * d0);
    chord(u_lo, std::min(u_hi, -h));
    chord(std::max(u_lo, h), u_hi);
  } else {
    chord(u_lo, u_hi);
  }
  return m;
}

const FlatJointGeometry& flat_joint_geometry(int dim, int Nr, int Nal) {
  static std::mutex mutex;
  static std::map<std::array<int, 3>, std::unique_ptr<FlatJointGeometry>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{dim, Nr, dim == 2 ? 1 : Nal}];
  if (!slot)
    slot = std::make_unique<FlatJointGeometry>(build_geometry(dim, Nr, Nal));
  return *slot;
}

} // namespace rocklab
