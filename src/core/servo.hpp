// The wall servo (PFC's servo-controlled walls): a wall moves so that the stress it exerts on the
// grains reaches a target. Genesis' vessel and the lab's platens and confining walls use it.
// Units SI.
#pragma once

#include <algorithm>
#include <vector>

namespace rocklab {

class Model;

/// The wall speed [m/s] that closes the fraction `gain` of the stress error [Pa] in one step of
/// dt [s], for a wall loading `area` [m^2] through contacts of stiffness sum `k_sum` [N/m]:
/// v = gain A / (k_sum dt) error, at most vmax either way; a wall without contacts moves at vmax.
/// v > 0 moves the wall into the specimen.
inline double servo_velocity(double gain, double area, double k_sum, double dt, double error,
                             double vmax) {
  const double v = k_sum > 0 ? gain * area / (k_sum * dt) * error : vmax;
  return std::clamp(v, -vmax, vmax);
}

/// The translational stiffness summed over each wall's contacts [N/m] (index = wall index), from
/// the last force update. `sums` is resized to the wall count and reused.
void wall_stiffness_sums(const Model& m, std::vector<double>& sums);

} // namespace rocklab
