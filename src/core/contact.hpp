// A contact between two pieces: the contact plane (FJ memo Eq. 2-6) and the resulting force.
#pragma once

#include "contact/registry.hpp"
#include "core/types.hpp"

#include <cstdint>

namespace rocklab {

enum class ContactKind : std::uint8_t { BallBall = 0, BallFacet = 1 };

/// Ordering key: contacts are kept sorted by it, which makes every loop order deterministic.
inline std::uint64_t contact_key(ContactKind kind, std::int32_t end1, std::int32_t end2) {
  return (static_cast<std::uint64_t>(end1) << 32) | (static_cast<std::uint64_t>(kind) << 31) |
         static_cast<std::uint32_t>(end2);
}

/// The pieces a contact key names (the inverse of contact_key).
struct ContactEnds {
  ContactKind kind = ContactKind::BallBall;
  std::int32_t end1 = -1, end2 = -1; ///< ball indices; end2 is the wall index for a facet
};
inline ContactEnds contact_ends(std::uint64_t key) {
  return {static_cast<ContactKind>((key >> 31) & 1u), static_cast<std::int32_t>(key >> 32),
          static_cast<std::int32_t>(key & 0x7fffffffu)};
}

struct Contact {
  std::uint64_t key = 0;
  std::int32_t end1 = -1;  ///< ball index
  std::int32_t end2 = -1;  ///< ball index (ball-ball) or wall index (ball-facet)
  std::int32_t facet = -1; ///< nearest facet of the wall (ball-facet)
  ContactKind kind = ContactKind::BallBall;
  ModelKind model = model_kind<Linear>;
  std::uint32_t slot = 0; ///< index into the model's batch
  bool initialized = false;
  Vec3 n = Vec3::UnitX(); ///< normal, from piece 1 to piece 2
  Vec3 s = Vec3::UnitY(); ///< contact-plane s axis
  Vec3 t = Vec3::UnitZ(); ///< contact-plane t axis, n = s x t
  double gap = 0;         ///< contact gap g_c, > 0 open [m]
};

/// What one force-displacement update produces for a contact, kept in its own compact array
/// (index = contact index) so that summing into bodies reads only this.
struct ContactOutput {
  Vec3 xc = Vec3::Zero();     ///< contact location [m]
  Vec3 force = Vec3::Zero();  ///< force on piece 2 at xc, global [N]
  Vec3 moment = Vec3::Zero(); ///< moment on piece 2, global [N m]
  ContactStiffness stiff;     ///< stiffness for the time-step estimate
};

/// A contact's part of its ball's stiffness sums for the time-step estimate (translation; rotation
/// about the ball's centre, `arm` from the centre to the contact point).
inline void add_ball_stiffness(const ContactStiffness& s, const Vec3& arm, double& k_tran,
                               double& k_rot) {
  k_tran += s.k_tran;
  k_rot += s.k_shear * arm.squaredNorm() + s.k_rot;
}

/// Force and moment in contact-plane coordinates (Fn > 0 tension).
inline ContactResult local_components(const Contact& c, const ContactOutput& o) {
  return {-o.force.dot(c.n), o.force.dot(c.s),  o.force.dot(c.t),
          o.moment.dot(c.n), o.moment.dot(c.s), o.moment.dot(c.t)};
}

} // namespace rocklab
