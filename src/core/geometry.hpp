// Contact resolution: contact plane and relative motion (FJ memo section 1.3, Eq. 2-11).
#pragma once

#include "contact/contact_model.hpp"
#include "core/contact.hpp"

namespace rocklab {

/// Location, normal and gap of a contact plane (Eq. 2).
struct PlaneGeometry {
  Vec3 xc, n;
  double gap;
};

/// Eq. 2 for ball-ball: the plane sits mid-way in the gap/overlap, normal from 1 to 2.
PlaneGeometry ball_ball_plane(const Vec3& x1, double R1, const Vec3& x2, double R2);
/// Eq. 2 for ball-facet: xf is the facet point closest to the ball centre.
PlaneGeometry ball_facet_plane(const Vec3& x1, double R1, const Vec3& xf);

/// Initial s axis of a new 3D contact: the projection of global x (or y, when x is nearly
/// parallel to n) onto the contact plane (FJ memo section 1.3.1).
Vec3 initial_s_axis(const Vec3& n);

/// Update s, t for a new normal (Eq. 5): rotate about the line common to the old and new planes,
/// then about the new normal by the mean spin of the two pieces. 2D uses Eq. 4 (s = -k).
void update_plane_axes(int dim, const Vec3& n_old, const Vec3& n_new, const Vec3& w1,
                       const Vec3& w2, double dt, Vec3& s, Vec3& t);

/// Relative displacement and rotation increments at the contact (Eq. 7-11), written into k.
/// xb1/xb2 are the body reference points (centroid, or wall centre of rotation).
void relative_increments(const Vec3& xc, const Vec3& n, const Vec3& s, const Vec3& t,
                         const Vec3& xb1, const Vec3& v1, const Vec3& w1, const Vec3& xb2,
                         const Vec3& v2, const Vec3& w2, double dt, ContactKinematics& k);

} // namespace rocklab
