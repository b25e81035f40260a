// Event stream: values produced in the cycle, buffered per step and drained in a fixed order.
#pragma once

#include "core/types.hpp"

#include <cstdint>
#include <vector>

namespace rocklab {

enum class EventType : std::uint8_t { ContactCreated, ContactDeleted, SlipChange, BondBreak };

inline const char* to_string(EventType t) {
  switch (t) {
  case EventType::ContactCreated:
    return "contact_created";
  case EventType::ContactDeleted:
    return "contact_deleted";
  case EventType::SlipChange:
    return "slip_change";
  case EventType::BondBreak:
    return "bond_break";
  }
  return "unknown";
}

/// One event. Fields that do not apply to a type are left at their defaults.
struct Event {
  EventType type = EventType::ContactCreated;
  std::int64_t step = 0;
  double time = 0;           ///< [s]
  std::uint64_t contact = 0; ///< contact key (see Contact::key)
  std::int32_t seq = 0;      ///< order of events raised by one contact within a step
  std::int32_t mode =
      0; ///< slip_change: 0 slip began, 1 slip ended; bond_break: 1 tension, 2 shear
  std::int32_t element = -1; ///< flat-joint element, -1 for the whole contact
  /// Location [m]. A contact model writes the offset from the contact location in contact-plane
  /// coordinates (0, s, t); the engine turns it into a global position.
  Vec3 position = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  double size = 0;     ///< crack size [m]
  double gap = 0;      ///< [m]
  double strength = 0; ///< failure strength [N or Pa, as the model states]
  double energy = 0;   ///< strain energy at failure [J]
};

/// A buffer that the contact loop appends to (one per thread); capacity is kept between steps.
using EventBuffer = std::vector<Event>;

} // namespace rocklab
