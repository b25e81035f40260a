// The fixtures a test mounts in the loading frame: what carries the load along the axis (flat
// platens, ISRM curved jaws, or grips holding the end grains) and the confining walls of a
// triaxial (2D: biaxial) test with their stress servo. A test chooses them (FrameTest::actuator,
// FrameTest::confinement); the frame (loading_frame.hpp) drives and reads them through these
// classes only. Units SI; forces and stresses compression positive.
#pragma once

#include "core/model.hpp"
#include "lab/frame/geometry.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rocklab {

/// Adds a wall of the machine with its ball-facet contact rule (ahead of the specimen's general
/// rule); returns the wall's index.
std::int64_t add_machine_wall(Model& m, Wall w, const LinearProps& props);

/// A plane wall of the machine through `p` with inward normal `n`, `extent` across [m].
Wall machine_wall(int dim, const std::string& name, const Vec3& p, const Vec3& n, double extent);

/// The speed [m/s] that closes a machine wall's stress error towards `target` in one step
/// (proportional control on the stiffness sum `k_sum` of its contacts [N/m] over `area` [m^2]),
/// capped at 0.1 % of a mean grain radius per step; > 0 towards the specimen.
double machine_servo_velocity(const Model& m, const SpecimenGeometry& g, double k_sum,
                              double target, double area, double stress);

/// The radius of ISRM curved jaws of `ratio` times the disk's radius (D as in 2F / (pi D t)) [m].
double curved_jaw_radius(double ratio, const SpecimenGeometry& g);

/// What closes on (or pulls) the specimen along the loading axis and carries the load.
class Actuator {
public:
  virtual ~Actuator() = default;
  /// Added to the model around the measured specimen (`contact`: the specimen's ball-facet
  /// linear model as the test wants it); errors name `file`.
  virtual void mount(Model& m, const SpecimenGeometry& g, const LinearProps& contact,
                     const std::string& file) = 0;
  /// Platens close, grips open, at v each [m/s].
  virtual void drive(Model& m, const SpecimenGeometry& g, double v) const = 0;
  /// The separation along the axis [m].
  virtual double separation(const Model& m, int axis) const = 0;
  /// The load [N] (2D per unit thickness): > 0 compresses (platens) or pulls (grips).
  virtual double force(const Model& m, int axis) const = 0;
  /// |F_top + F_bottom| / (|F_top| + |F_bottom|), or -1 where it does not apply (grips).
  virtual double imbalance(const Model& /*m*/, int /*axis*/) const { return -1; }
  /// The top platen's wall (its contacts give the seating servo's gain); -1: no wall (grips
  /// neither seat nor re-seat).
  virtual std::int64_t wall() const { return -1; }
  /// Checkpoint state (the frame's state object) and its restoration, indices checked.
  virtual void save(nlohmann::json& state) const = 0;
  virtual void restore(const nlohmann::json& state, const std::string& file, const Model& m) = 0;
};

/// Flat platens, or curved jaws on a disk loaded across its diameter.
class Platens final : public Actuator {
public:
  /// jaw_ratio > 0: ISRM curved jaws of this times the disk's radius (diametral specimens);
  /// friction: the platens' ball-facet friction coefficient (none: the contact's own);
  /// stiffness: the platens' contact stiffness over the contact's own, (0, 1] (< 1: a cushion).
  Platens(double jaw_ratio, std::optional<double> friction, double stiffness = 1)
      : jaw_ratio_(jaw_ratio), friction_(friction), stiffness_(stiffness) {}
  void mount(Model& m, const SpecimenGeometry& g, const LinearProps& contact,
             const std::string& file) override;
  void drive(Model& m, const SpecimenGeometry& g, double v) const override;
  double separation(const Model& m, int axis) const override;
  double force(const Model& m, int axis) const override;
  double imbalance(const Model& m, int axis) const override;
  std::int64_t wall() const override { return top_; }
  void save(nlohmann::json& state) const override;
  void restore(const nlohmann::json& state, const std::string& file, const Model& m) override;

private:
  Wall curved_jaw(const Model& m, const SpecimenGeometry& g, const std::string& name,
                  int side) const;
  double jaw_ratio_;
  std::optional<double> friction_;
  double stiffness_;
  std::int64_t top_ = -1, bottom_ = -1;
};

/// Grips holding the grains within `fraction` of the height from each end (direct tension).
class Grips final : public Actuator {
public:
  explicit Grips(double fraction) : fraction_(fraction) {}
  void mount(Model& m, const SpecimenGeometry& g, const LinearProps& contact,
             const std::string& file) override;
  void drive(Model& m, const SpecimenGeometry& g, double v) const override;
  double separation(const Model& m, int axis) const override;
  double force(const Model& m, int axis) const override;
  void save(nlohmann::json& state) const override;
  void restore(const nlohmann::json& state, const std::string& file, const Model& m) override;

private:
  double fraction_;
  std::vector<std::int32_t> top_, bottom_;
};

/// Confining walls: a cylinder around a round specimen, plates on the faces of a prism (2D: on
/// the sides), each servo-controlled to the confining stress.
class ConfiningWalls {
public:
  /// Walls that hold `target` [Pa]; the confining phase ends once every wall is within
  /// `tolerance` x target of it.
  ConfiningWalls(double target, double tolerance) : target_(target), tolerance_(tolerance) {}
  double target() const { return target_; }       ///< the confining stress [Pa]
  double tolerance() const { return tolerance_; } ///< the confining phase's band [-]
  void mount(Model& m, const SpecimenGeometry& g, const LinearProps& contact);
  const std::vector<std::int64_t>& walls() const { return walls_; }
  /// The mean stress on the walls [Pa]; `height`: the specimen's height now [m].
  double mean_stress(const Model& m, const SpecimenGeometry& g, double height) const;
  /// Every wall's stress within tol x target of `target` [Pa].
  bool within(const Model& m, const SpecimenGeometry& g, double height, double target,
              double tol) const;
  /// The section the walls enclose [m^2] (2D: the width x unit thickness).
  double area(const Model& m, const SpecimenGeometry& g) const;
  /// The walls' lateral strain since loading began, compression positive [-].
  double strain(const Model& m, const SpecimenGeometry& g) const;
  /// The walls' widths (the cylinder's radius) when loading begins.
  void mark_reference(const Model& m, const SpecimenGeometry& g);
  /// One servo step towards the confining stress: each wall follows the grains that touch it
  /// and closes its stress error (`wall_k`: the stiffness sum of each wall's contacts,
  /// wall_stiffness_sums).
  void control(Model& m, const SpecimenGeometry& g, double height,
               const std::vector<double>& wall_k);
  /// Checkpoint fields (the frame's state object's keys).
  template <class A> void fields(A& a) {
    a("lateral", walls_), a("lateral_axis", axis_), a("lateral_sign", sign_);
    a("lateral_ref", ref_), a("servo_integral", integral_);
  }
  /// After a restoration: the walls exist and the lists agree; errors name `file`.
  void check(const Model& m, const std::string& file) const;

private:
  double width(const Model& m, int d) const;
  double face_area(const Model& m, const SpecimenGeometry& g, double height, std::size_t k) const;
  double stress(const Model& m, const SpecimenGeometry& g, double height, std::size_t k) const;
  void gather_follow_sums(const Model& m);
  double target_, tolerance_;
  std::vector<std::int64_t> walls_;
  std::vector<int> axis_;        ///< axis of each (-1: the cylinder)
  std::vector<double> sign_;     ///< +1 for the wall on the + side
  Vec3 ref_ = Vec3::Zero();      ///< widths (cylinder radius in [0]) when loading began
  std::vector<double> integral_; ///< sum of each wall's stress error [Pa]
  // per-step sums by wall index (reused buffers)
  std::vector<double> wall_f_, wall_fv_;
  std::vector<int> of_wall_;
};

} // namespace rocklab
