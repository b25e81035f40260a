// From crack records to what a rock engineer reads: one crack per broken contact (its damage =
// broken parts / parts; a flat joint's elements become one crack) and fracture (acoustic-emission)
// events, formed while the test runs by lab/ae_monitor (Hazzard & Young 2000, 2004), with their
// sources' moment tensors. Units SI.
#pragma once

#include "lab/ae_monitor.hpp"
#include "lab/crack_monitor.hpp"

#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

namespace rocklab {

/// One broken contact as of some time: its element cracks merged.
struct ContactCrack {
  std::uint64_t contact = 0;
  std::int64_t ball1 = 0, ball2 = 0;
  Vec3 position = Vec3::Zero(); ///< area-weighted centre of its cracks [m]
  Vec3 normal = Vec3::UnitZ();  ///< the first crack's normal
  double size = 0;              ///< diameter (3D) / length (2D) of the summed crack area [m]
  double time = 0;              ///< first break [s]
  int broken = 0;               ///< parts broken (flat-joint elements; 1 for a point bond)
  int parts = 1;                ///< parts of the bond
  int tension = 0, shear = 0;   ///< of the broken parts
  double energy = 0;            ///< released by its breaks [J]
  int event = -1;               ///< the event of its first crack
  double damage() const { return static_cast<double>(broken) / std::max(parts, 1); }
  int mode() const { return tension >= shear ? 1 : 2; }
};

/// A fracture event: cracks near in space and time.
struct FractureEvent {
  int id = 0;
  double time = 0;              ///< its first crack [s]
  double duration = 0;          ///< last crack - first crack [s]
  Vec3 position = Vec3::Zero(); ///< centroid of its cracks [m]
  int cracks = 0, contacts = 0, tension = 0, shear = 0;
  double energy = 0;          ///< strain energy released by its cracks [J]
  double magnitude = 0;       ///< energy magnitude (log10 E = 1.5 M + 4.8, E in J)
  bool has_source = false;    ///< its moment tensor was followed (lab/ae_monitor)
  Mat3 tensor = Mat3::Zero(); ///< moment tensor at its largest scalar moment [N m]
  SourceReading source;       ///< what that tensor reads (M0, Mw, type, axes)
};

/// The events of a test's cracks: which event each crack record belongs to (from the
/// AeMonitor), their sources by event id, and the events with everything summed.
struct EventClustering {
  std::vector<int> event_of_crack; ///< per crack record
  std::vector<AeSource> sources;   ///< by event id (empty: no moment tensors)
  int dim = 3;
  std::vector<FractureEvent> events;
};

/// The events of `cracks` as `monitor` formed them.
EventClustering monitored_events(const std::vector<Crack>& cracks, const AeMonitor& monitor,
                                 int dim);

/// The broken contacts as of `until` (cracks with time <= until), in order of first break. Size:
/// 3D the diameter of the summed crack area, 2D the summed length.
std::vector<ContactCrack> contact_cracks(const std::vector<Crack>& cracks,
                                         const EventClustering& ev, double until, int dim);

/// The events as of `until` (their cracks up to then).
std::vector<FractureEvent> events_until(const std::vector<Crack>& cracks, const EventClustering& ev,
                                        double until);

/// events.csv: one row per event, SI units (tensors in N m; 2D per metre of thickness).
void write_events_csv(std::ostream& out, const std::vector<FractureEvent>& events);

} // namespace rocklab
