#include "core/geometry.hpp"

#include <cmath>

namespace rocklab {

PlaneGeometry ball_ball_plane(const Vec3& x1, double R1, const Vec3& x2, double R2) {
  const Vec3 dx = x2 - x1;
  const double d = dx.norm();
  const Vec3 n = d > 0 ? Vec3(dx / d) : Vec3::UnitX();
  const double gap = d - (R1 + R2);
  return {x1 + (R1 + 0.5 * gap) * n, n, gap}; // Eq. 2
}

PlaneGeometry ball_facet_plane(const Vec3& x1, double R1, const Vec3& xf) {
  const Vec3 dx = xf - x1;
  const double d = dx.norm();
  const Vec3 n = d > 0 ? Vec3(dx / d) : Vec3::UnitX();
  const double gap = d - R1;
  return {x1 + (R1 + 0.5 * gap) * n, n, gap}; // Eq. 2
}

Vec3 initial_s_axis(const Vec3& n) {
  const Vec3 g = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (g - g.dot(n) * n).normalized();
}

void update_plane_axes(int dim, const Vec3& n_old, const Vec3& n_new, const Vec3& w1,
                       const Vec3& w2, double dt, Vec3& s, Vec3& t) {
  if (dim == 2) {
    s = -Vec3::UnitZ();             // 2D convention of Table 1
    t = Vec3::UnitZ().cross(n_new); // Eq. 4
    return;
  }
  // Eq. 5 applies two small rotations to s in linearised form. We apply the same two rotations
  // exactly (Rodrigues): the linearised form is not a rotation, so it would make the stored
  // shear components depend on the arbitrary initial choice of s at second order per step,
  // which breaks rotational invariance. The first rotation is about the line common to the old
  // and new planes, by the angle between the normals...
  const Vec3 axis = n_old.cross(n_new);
  const double sin_a = axis.norm(), cos_a = n_old.dot(n_new);
  if (sin_a > 0) {
    const Vec3 k = axis / sin_a;
    s = s * cos_a + k.cross(s) * sin_a + k * (k.dot(s) * (1 - cos_a));
  }
  // ...the second about the new normal by the mean spin of the two pieces times dt.
  const double angle = 0.5 * (w1 + w2).dot(n_new) * dt;
  if (angle != 0) {
    const double c = std::cos(angle), sn = std::sin(angle);
    s = s * c + n_new.cross(s) * sn + n_new * (n_new.dot(s) * (1 - c));
  }
  // Keep the frame orthonormal to round-off over millions of steps.
  s -= s.dot(n_new) * n_new;
  s.normalize();
  t = n_new.cross(s); // n = s x t
}

void relative_increments(const Vec3& xc, const Vec3& n, const Vec3& s, const Vec3& t,
                         const Vec3& xb1, const Vec3& v1, const Vec3& w1, const Vec3& xb2,
                         const Vec3& v2, const Vec3& w2, double dt, ContactKinematics& k) {
  // Eq. 8: velocity of the point of each body that coincides with the contact location.
  const Vec3 vc1 = v1 + w1.cross(xc - xb1);
  const Vec3 vc2 = v2 + w2.cross(xc - xb2);
  const Vec3 d_delta = (vc2 - vc1) * dt; // Eq. 7, 11
  const Vec3 d_theta = (w2 - w1) * dt;
  k.d_dn = d_delta.dot(n); // Eq. 9
  const Vec3 d_ds = d_delta - k.d_dn * n;
  k.d_dss = d_ds.dot(s);
  k.d_dst = d_ds.dot(t);
  k.d_tt = d_theta.dot(n); // Eq. 10
  const Vec3 d_tb = d_theta - k.d_tt * n;
  k.d_tbs = d_tb.dot(s);
  k.d_tbt = d_tb.dot(t);
}

} // namespace rocklab
