#include "lab/moment_tensor.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace rocklab {

namespace {

// An axis has no sign: the component largest in magnitude is made positive.
Vec3 signed_axis(Vec3 v) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(v[i]) > std::abs(v[k]))
      k = i;
  return v[k] < 0 ? Vec3(-v) : v;
}

} // namespace

const char* to_string(SourceClass c) {
  switch (c) {
  case SourceClass::Tensile:
    return "tensile";
  case SourceClass::Shear:
    return "shear";
  case SourceClass::Implosive:
    return "implosive";
  }
  return "shear";
}

double moment_magnitude(double m0) {
  return m0 > 0 ? 2.0 / 3.0 * std::log10(m0) - 6.0 : std::numeric_limits<double>::quiet_NaN();
}

double feignier_young_r(const Vec3& ev, int dim) {
  double tr = 0;
  for (int i = 0; i < dim; ++i)
    tr += ev[i];
  double dev = 0;
  for (int i = 0; i < dim; ++i)
    dev += std::abs(ev[i] - tr / dim);
  const double den = std::abs(tr) + dev;
  return den > 0 ? 100 * tr / den : 0;
}

SourceClass source_class(double r) {
  return r > 30 ? SourceClass::Tensile : r < -30 ? SourceClass::Implosive : SourceClass::Shear;
}

SourceReading read_source(const Mat3& m_in, int dim) {
  SourceReading s;
  const Mat3 m = 0.5 * (m_in + m_in.transpose());
  Vec3 ev = Vec3::Zero(); // descending
  if (dim == 2) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(m.topLeftCorner<2, 2>());
    ev = Vec3(es.eigenvalues()[1], es.eigenvalues()[0], 0);
    s.t_axis = signed_axis(Vec3(es.eigenvectors()(0, 1), es.eigenvectors()(1, 1), 0));
    s.p_axis = signed_axis(Vec3(es.eigenvectors()(0, 0), es.eigenvectors()(1, 0), 0));
  } else {
    Eigen::SelfAdjointEigenSolver<Mat3> es(m);
    ev = Vec3(es.eigenvalues()[2], es.eigenvalues()[1], es.eigenvalues()[0]);
    s.t_axis = signed_axis(es.eigenvectors().col(2));
    s.p_axis = signed_axis(es.eigenvectors().col(0));
  }
  s.eigenvalues = ev;
  s.m0 = std::sqrt(0.5 * ev.squaredNorm()); // Silver & Jordan (1982)
  s.mw = moment_magnitude(s.m0);
  s.r = feignier_young_r(ev, dim);
  s.type = source_class(s.r);
  // Shares after Vavrycuk (2001, 2015): the isotropic part against the largest deviatoric
  // eigenvalue, the CLVD from the deviatoric eigenvalues' ratio eps (0 pure DC, +-0.5 pure CLVD).
  double iso = 0;
  for (int i = 0; i < dim; ++i)
    iso += ev[i] / dim;
  double big = 0, small = std::numeric_limits<double>::infinity(), small_signed = 0;
  for (int i = 0; i < dim; ++i) {
    const double d = ev[i] - iso;
    big = std::max(big, std::abs(d));
    if (std::abs(d) < small)
      small = std::abs(d), small_signed = d;
  }
  if (std::abs(iso) + big <= 0)
    return s; // a zero tensor: no source
  s.isotropic = iso / (std::abs(iso) + big);
  // A 2D (plane) tensor's deviatoric part is a double couple: its two deviatoric eigenvalues are
  // equal and opposite, and the out-of-plane one is not known.
  const double eps = dim == 3 && big > 0 ? -small_signed / big : 0;
  s.clvd = 2 * eps * (1 - std::abs(s.isotropic));
  s.double_couple = std::max(0.0, 1 - std::abs(s.isotropic) - std::abs(s.clvd));
  return s;
}

} // namespace rocklab
