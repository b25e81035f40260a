// Contact resolution: contact plane and relative motion (FJ memo section 1.3, Eq. 2-11).
#pragma once

#include "contact/contact_model.hpp"
#include "core/contact.hpp"

#include <cmath>

namespace rocklab {

/// Location, normal and gap of a contact plane (Eq. 2).
struct PlaneGeometry {
  Vec3 xc, n;
  double gap;
};

/// cos and sin of an angle; per-step rotation angles are tiny, where a short series is exact to
/// double precision (the first omitted term is below 1e-20 for |a| < 1e-3).
inline void small_angle_cos_sin(double a, double& c, double& s) {
  if (std::abs(a) < 1e-3) {
    const double a2 = a * a;
    c = 1 - a2 / 2 * (1 - a2 / 12 * (1 - a2 / 30));
    s = a * (1 - a2 / 6 * (1 - a2 / 20 * (1 - a2 / 42)));
  } else {
    c = std::cos(a);
    s = std::sin(a);
  }
}

/// Eq. 2 for ball-ball: the plane sits mid-way in the gap/overlap, normal from 1 to 2.
inline PlaneGeometry ball_ball_plane(const Vec3& x1, double R1, const Vec3& x2, double R2) {
  const Vec3 dx = x2 - x1;
  const double d = dx.norm();
  const Vec3 n = d > 0 ? Vec3(dx / d) : Vec3::UnitX();
  const double gap = d - (R1 + R2);
  return {x1 + (R1 + 0.5 * gap) * n, n, gap}; // Eq. 2
}

/// Eq. 2 for ball-facet: xf is the facet point closest to the ball centre.
inline PlaneGeometry ball_facet_plane(const Vec3& x1, double R1, const Vec3& xf) {
  const Vec3 dx = xf - x1;
  const double d = dx.norm();
  const Vec3 n = d > 0 ? Vec3(dx / d) : Vec3::UnitX();
  const double gap = d - R1;
  return {x1 + (R1 + 0.5 * gap) * n, n, gap}; // Eq. 2
}

/// Initial s axis of a new 3D contact: the projection of global x (or y, when x is nearly
/// parallel to n) onto the contact plane (FJ memo section 1.3.1).
inline Vec3 initial_s_axis(const Vec3& n) {
  const Vec3 g = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (g - g.dot(n) * n).normalized();
}

/// Update s, t for a new normal (Eq. 5): rotate about the line common to the old and new planes,
/// then about the new normal by the mean spin of the two pieces. 2D uses Eq. 4 (s = -k).
inline void update_plane_axes(int dim, const Vec3& n_old, const Vec3& n_new, const Vec3& w1,
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
  // The rotation taking n_old to n_new, in the sqrt-free Rodrigues form: with a = n_old x n_new
  // and c = n_old . n_new, R s = c s + a x s + a (a . s) / (1 + c).
  const Vec3 axis = n_old.cross(n_new);
  const double cos_a = n_old.dot(n_new);
  if (cos_a > -0.5) // a normal cannot turn by more than 120 degrees in one step
    s = cos_a * s + axis.cross(s) + axis * (axis.dot(s) / (1 + cos_a));
  // ...the second about the new normal by the mean spin of the two pieces times dt.
  const double angle = 0.5 * (w1 + w2).dot(n_new) * dt;
  if (angle != 0) {
    double c, sn;
    small_angle_cos_sin(angle, c, sn);
    s = s * c + n_new.cross(s) * sn + n_new * (n_new.dot(s) * (1 - c));
  }
  // Keep the frame orthonormal to round-off over millions of steps: project out n, then one
  // Newton step towards unit length (|s| differs from 1 only by round-off here).
  s -= s.dot(n_new) * n_new;
  s *= 0.5 * (3.0 - s.squaredNorm());
  t = n_new.cross(s); // n = s x t
}

/// Relative displacement and rotation increments at the contact (Eq. 7-11), written into k.
/// xb1/xb2 are the body reference points (centroid, or wall centre of rotation).
inline void relative_increments(const Vec3& xc, const Vec3& n, const Vec3& s, const Vec3& t,
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
