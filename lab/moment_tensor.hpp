// What a seismologist reads from an acoustic-emission event's moment tensor: its scalar moment
// and moment magnitude, its source type (isotropic, double-couple and CLVD shares; Feignier &
// Young's R and class) and its principal axes. Units SI: tensors and moments in N m (2D: per
// metre of the specimen's unit thickness).
#pragma once

#include "core/types.hpp"

#include <Eigen/Core>
#include <string>

namespace rocklab {

using Mat3 = Eigen::Matrix3d;

/// Feignier & Young (1992) classes of R.
enum class SourceClass { Tensile, Shear, Implosive };
const char* to_string(SourceClass c);

/// A symmetric moment tensor's reading.
struct SourceReading {
  double m0 = 0;            ///< scalar moment (sum of squared eigenvalues / 2)^(1/2) [N m]
  double mw = 0;            ///< moment magnitude 2/3 log10 M0 - 6 (NaN for M0 = 0) [-]
  double isotropic = 0;     ///< signed isotropic share, [-1, 1] (> 0 opening) [-]
  double double_couple = 0; ///< double-couple share, [0, 1] [-]
  double clvd = 0;          ///< signed CLVD share, [-1, 1] (0 in 2D) [-]
  double r = 0;             ///< Feignier & Young's R, [-100, 100] [-]
  SourceClass type = SourceClass::Shear;
  Vec3 t_axis = Vec3::UnitX();     ///< tension axis: eigenvector of the largest eigenvalue (unit)
  Vec3 p_axis = Vec3::UnitY();     ///< pressure axis: eigenvector of the smallest eigenvalue (unit)
  Vec3 eigenvalues = Vec3::Zero(); ///< descending (2D: the in-plane two, third 0) [N m]
};

/// The reading of moment tensor `m` (symmetrized; in 2D only its x-y block is read).
SourceReading read_source(const Mat3& m, int dim);

/// Moment magnitude from the scalar moment M0 [N m] (Hanks & Kanamori 1979): 2/3 log10 M0 - 6.
double moment_magnitude(double m0);

/// Feignier & Young's R (1992): 100 tr M / (|tr M| + sum of the deviatoric eigenvalues' absolute
/// values), from the eigenvalues (dim of them).
double feignier_young_r(const Vec3& eigenvalues, int dim);

/// R above +30 tensile, below -30 implosive, else shear (Feignier & Young 1992).
SourceClass source_class(double r);

} // namespace rocklab
