// Crack monitoring: every bond_break event becomes a crack record (a disk in 3D, a segment of unit
// depth in 2D; FJ memo footnote 3). Records are kept in event order. Units SI.
#pragma once

#include "core/model.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace rocklab {

struct Crack {
  double time = 0;                   ///< [s]
  std::int64_t step = 0;             ///< model step of the break
  Vec3 position = Vec3::Zero();      ///< [m]
  Vec3 normal = Vec3::Zero();        ///< unit normal of the crack plane (the contact normal)
  double size = 0;                   ///< diameter (3D) or length (2D) [m]
  int mode = 0;                      ///< 1 tension, 2 shear
  std::int64_t ball1 = 0, ball2 = 0; ///< ids of the two grains
  std::uint64_t contact = 0;         ///< contact key
  int element = -1;                  ///< flat-joint element (1..N), -1 for a whole bond
  int parts = 1;                     ///< bondable parts of its contact (flat-joint elements)
  double gap = 0;                    ///< contact gap at the break [m]
  double strength = 0;               ///< the strength that was exceeded [Pa]
  double energy = 0;                 ///< strain energy released by the break [J]
};

class CrackMonitor {
public:
  /// Turn the bond_break events among `events` into cracks (other events are ignored).
  void consume(const Model& m, const std::vector<Event>& events);
  const std::vector<Crack>& cracks() const { return cracks_; }
  std::int64_t tension() const { return tension_; }
  std::int64_t shear() const { return shear_; }
  std::int64_t total() const { return static_cast<std::int64_t>(cracks_.size()); }
  /// cracks.csv: one row per crack, SI units.
  void write_csv(std::ostream& out) const;
  nlohmann::json to_json() const; ///< for checkpoints
  void from_json(const nlohmann::json& j);

private:
  std::vector<Crack> cracks_;
  std::int64_t tension_ = 0, shear_ = 0;
};

} // namespace rocklab
