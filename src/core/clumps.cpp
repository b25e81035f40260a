#include "core/clumps.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rocklab {

namespace {

constexpr double kPi = std::numbers::pi;

// Inertia tensor of a point-like offset d for mass m (parallel-axis term).
Eigen::Matrix3d shift(double m, const Vec3& d) {
  return m * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
}

} // namespace

MassProperties union_mass_properties(const std::vector<Pebble>& pebbles, double density, int dim) {
  if (pebbles.empty())
    throw std::invalid_argument("a clump needs at least one pebble");
  MassProperties mp;
  bool overlap = false;
  for (std::size_t a = 0; a < pebbles.size() && !overlap; ++a)
    for (std::size_t b = a + 1; b < pebbles.size(); ++b) {
      const double d = (pebbles[a].position - pebbles[b].position).norm();
      if (d < (pebbles[a].radius + pebbles[b].radius) * (1 - 1e-12)) {
        overlap = true;
        break;
      }
    }
  if (!overlap) {
    // Disjoint pebbles: exact sums.
    std::vector<double> m(pebbles.size());
    for (std::size_t a = 0; a < pebbles.size(); ++a) {
      const double r = pebbles[a].radius;
      m[a] = dim == 2 ? density * kPi * r * r : density * 4.0 / 3.0 * kPi * r * r * r;
      mp.mass += m[a];
      mp.centroid += m[a] * pebbles[a].position;
    }
    mp.centroid /= mp.mass;
    for (std::size_t a = 0; a < pebbles.size(); ++a) {
      const double r = pebbles[a].radius;
      Eigen::Matrix3d own = Eigen::Matrix3d::Zero();
      if (dim == 2) {
        // unit-thickness disk: only the in-plane rotation matters (I_zz = m r^2 / 2)
        own(2, 2) = 0.5 * m[a] * r * r;
        own(0, 0) = own(1, 1) = 0.25 * m[a] * r * r;
      } else {
        own = 0.4 * m[a] * r * r * Eigen::Matrix3d::Identity();
      }
      mp.inertia += own + shift(m[a], pebbles[a].position - mp.centroid);
    }
    mp.exact = true;
    return mp;
  }
  // Overlapping pebbles: midpoint integration over a regular grid (union counted once).
  mp.exact = false;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Pebble& p : pebbles) {
    lo = lo.cwiseMin(p.position - Vec3::Constant(p.radius));
    hi = hi.cwiseMax(p.position + Vec3::Constant(p.radius));
  }
  const int n = dim == 2 ? kUnionGrid2D : kUnionGrid3D;
  const Vec3 h = (hi - lo) / n;
  const double cell = dim == 2 ? h.x() * h.y() : h.x() * h.y() * h.z();
  double m0 = 0;
  Vec3 m1 = Vec3::Zero();
  Eigen::Matrix3d m2 = Eigen::Matrix3d::Zero(); // sum of x x^T (relative to lo)
  const int nz = dim == 2 ? 1 : n;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec3 rel((i + 0.5) * h.x(), (j + 0.5) * h.y(), dim == 2 ? 0.0 : (k + 0.5) * h.z());
        Vec3 x = lo + rel;
        if (dim == 2)
          x.z() = pebbles[0].position.z();
        bool inside = false;
        for (const Pebble& p : pebbles)
          if ((x - p.position).squaredNorm() <= p.radius * p.radius) {
            inside = true;
            break;
          }
        if (!inside)
          continue;
        m0 += 1;
        m1 += rel;
        m2 += rel * rel.transpose();
      }
  mp.mass = density * cell * m0;
  const Vec3 c_rel = m1 / m0;
  mp.centroid = lo + c_rel;
  if (dim == 2)
    mp.centroid.z() = pebbles[0].position.z();
  // second moment about the centroid: S = sum (x - c)(x - c)^T, plus each cell's own h^2/12
  Eigen::Matrix3d S = density * cell * (m2 - m0 * c_rel * c_rel.transpose());
  const double own = density * cell * m0 / 12.0;
  S(0, 0) += own * h.x() * h.x();
  S(1, 1) += own * h.y() * h.y();
  if (dim == 3)
    S(2, 2) += own * h.z() * h.z();
  mp.inertia = S.trace() * Eigen::Matrix3d::Identity() - S;
  if (dim == 2) {
    // unit thickness: in-plane moments only through I_zz
    mp.inertia(0, 2) = mp.inertia(2, 0) = mp.inertia(1, 2) = mp.inertia(2, 1) = 0;
  }
  return mp;
}

std::vector<Pebble> clump_template(const std::string& name, int dim) {
  std::vector<Vec3> c;
  if (name == "single") {
    c = {Vec3::Zero()};
  } else if (name == "pair") {
    c = {Vec3(-1, 0, 0), Vec3(1, 0, 0)};
  } else if (name == "line3") {
    c = {Vec3(-2, 0, 0), Vec3(0, 0, 0), Vec3(2, 0, 0)};
  } else if (name == "triangle3") {
    // equilateral triangle of side 2 (mutually touching), one vertex up
    const double h = std::sqrt(3.0);
    c = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, h, 0)};
  } else if (name == "tetra4" && dim == 3) {
    const double h = std::sqrt(3.0);
    c = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, h, 0), Vec3(0, h / 3, 2 * std::sqrt(2.0 / 3.0))};
  } else {
    throw std::invalid_argument("unknown clump template \"" + name + "\"");
  }
  Vec3 mean = Vec3::Zero();
  for (const Vec3& x : c)
    mean += x;
  mean /= static_cast<double>(c.size());
  std::vector<Pebble> p;
  for (const Vec3& x : c)
    p.push_back({x - mean, 1.0});
  return p;
}

Vec3 Clump::angular_velocity() const {
  const Vec3 Lb = q.conjugate() * L;
  return q * Lb.cwiseQuotient(inertia);
}

double Clump::kinetic_rotational() const {
  const Vec3 Lb = q.conjugate() * L;
  return 0.5 * Lb.cwiseProduct(Lb).cwiseQuotient(inertia).sum();
}

void free_rotation(Eigen::Quaterniond& q, Vec3& Lb, const Vec3& I, double h, int dim) {
  // Exact flow of H_k = Lb_k^2 / (2 I_k): the body turns by phi = t Lb_k / I_k about its axis
  // k, and the body-frame momentum turns by -phi about the same axis.
  auto sub = [&](int k, double t) {
    const double phi = t * Lb[k] / I[k];
    if (phi == 0)
      return;
    q = q * Eigen::Quaterniond(Eigen::AngleAxisd(phi, Vec3::Unit(k)));
    Lb = Eigen::AngleAxisd(-phi, Vec3::Unit(k)) * Lb;
  };
  if (dim == 2) {
    sub(2, h);
  } else {
    sub(0, 0.5 * h);
    sub(1, 0.5 * h);
    sub(2, h);
    sub(1, 0.5 * h);
    sub(0, 0.5 * h);
  }
  q.normalize();
}

} // namespace rocklab
