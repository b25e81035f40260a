// Where a specimen deforms unlike its surroundings: the non-affine part of each grain's motion
// relative to its neighbours (D^2_min of Falk & Langer, Phys. Rev. E 57, 7192, 1998), made
// dimensionless. A macro-fracture or shear band shows as a zone of grains whose neighbours moved
// apart or slid past them, while intact rock (however strained, even rotated) stays near zero.
// Units: positions and displacements in m; the measure is dimensionless.
#pragma once

#include "core/types.hpp"

#include <cstddef>
#include <vector>

namespace rocklab {

/// For each grain i with reference position X_i = pos_i - disp_i: the local deformation gradient
/// F_i that best maps the reference branch vectors X_j - X_i of its neighbours j onto the current
/// ones x_j - x_i (least squares), and the non-affine strain
///   sqrt( sum_j |x_j - x_i - F_i (X_j - X_i)|^2 / sum_j |X_j - X_i|^2 ),
/// the rms misfit relative to the rms branch length: 0 for any affine motion (uniform strain,
/// rigid rotation, translation). `dim` 2 fits a 2 x 2 F in the xy plane. A grain with fewer than
/// dim + 1 neighbours, or whose neighbours do not span the space, gets 0.
std::vector<double> nonaffine_strain(const std::vector<Vec3>& pos, const std::vector<Vec3>& disp,
                                     const std::vector<std::vector<std::size_t>>& neighbours,
                                     int dim);

} // namespace rocklab
