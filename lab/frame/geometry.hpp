// The specimen as the loading frame measured it when the test began: what the fixtures are placed
// around and what strains and stresses refer to. Units SI [m, m^2, m^3].
#pragma once

#include "core/types.hpp"

#include <algorithm>

namespace rocklab {

struct SpecimenGeometry {
  int dim = 3;
  int axis = 2;           ///< loading axis: z (3D) / y (2D); a diametral test loads along y
  bool round = false;     ///< cylinder (3D) cross-section
  bool diametral = false; ///< a disk loaded across its diameter
  Vec3 center = Vec3::Zero();
  double height0 = 0;         ///< along the loading axis
  Vec3 width0 = Vec3::Zero(); ///< extents across the axis (cylinder: the diameter)
  double thickness = 1;       ///< disk thickness (2D: unit thickness)
  double area0 = 0, volume = 0, r_avg = 0;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero(); ///< the grains' bounding box (2D: z = 0)

  /// The length a strain rate refers to: the diameter across which a disk is loaded, else the
  /// height.
  double loaded_length() const { return diametral ? width0.y() : height0; }
  /// How far the machine's plane walls reach across: three times the specimen's largest size.
  double machine_span() const { return 3 * std::max({width0.maxCoeff(), height0, thickness}); }
  template <class A> void fields(A& a) {
    a("dim", dim), a("axis", axis), a("round", round), a("diametral", diametral);
    a("center", center), a("height0", height0), a("width0", width0), a("thickness", thickness);
    a("area0", area0), a("volume", volume), a("r_avg", r_avg), a("lo", lo), a("hi", hi);
  }
};

/// The unit vector along `axis` (0 x, 1 y, 2 z).
inline Vec3 unit_axis(int axis) {
  Vec3 e = Vec3::Zero();
  e[axis] = 1;
  return e;
}

} // namespace rocklab
