// Driving the frame each step: the confining walls' servo (feed-forward on the grains they touch,
// a proportional term and an integral trim), the seating servo of the platens, and the platens or
// grips at the loading rate (smoothly ramped) while loading and unloading.
#include "lab/frame/loading_frame.hpp"

#include "core/servo.hpp"

#include <algorithm>

namespace rocklab {

namespace {

constexpr double kServoIntegralSteps = 100; ///< integral time of the confining servo [steps]
/// Servo gain: the fraction of the stress error closed per step, from the stiffness of the wall's
/// contacts (1: the whole error, the fastest stable proportional control for a stiff contact).
constexpr double kServoGain = 1.0;

Vec3 unit(int axis) {
  Vec3 e = Vec3::Zero();
  e[axis] = 1;
  return e;
}

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

} // namespace

void LoadingFrame::gather_wall_sums() {
  // Per wall: the stiffness sum of its contacts (servo gain) and, for confining walls, the
  // force-weighted inward velocity of the grains touching it (feed-forward). Buffers are reused:
  // nothing is allocated per step.
  wall_stiffness_sums(m_, wall_k_);
  const std::size_t nw = m_.walls.size();
  wall_f_.assign(nw, 0.0);
  wall_fv_.assign(nw, 0.0);
  if (lateral_.empty())
    return;
  lateral_of_wall_.assign(nw, -1);
  for (std::size_t k = 0; k < lateral_.size(); ++k)
    lateral_of_wall_[static_cast<std::size_t>(lateral_[k])] = static_cast<int>(k);
  const auto& cs = m_.contacts();
  const auto& os = m_.contact_outputs();
  for (std::size_t ci = 0; ci < cs.size(); ++ci) {
    if (cs[ci].kind != ContactKind::BallFacet)
      continue;
    const auto wall = static_cast<std::size_t>(cs[ci].end2);
    const int k = lateral_of_wall_[wall];
    if (k < 0)
      continue;
    const double f = os[ci].force.norm();
    if (f <= 0)
      continue;
    const Wall& w = m_.walls[wall];
    const auto b = static_cast<std::size_t>(cs[ci].end1);
    const Vec3& vel = m_.balls.vel[b];
    const auto kk = static_cast<std::size_t>(k);
    double inward;
    if (lateral_axis_[kk] < 0) {
      Vec3 r = m_.balls.pos[b] - w.center;
      r -= r.dot(w.axis) * w.axis;
      const double rn = r.norm();
      inward = rn > 0 ? -vel.dot(r) / rn : 0.0;
    } else {
      inward = -lateral_sign_[kk] * vel[lateral_axis_[kk]];
    }
    wall_f_[wall] += f;
    wall_fv_[wall] += f * inward;
  }
}

double LoadingFrame::servo_velocity(std::size_t wall, double target, double area,
                                    double stress) const {
  // Close the stress error in one step, capped at 0.1 % of a mean grain radius per step.
  // Needs gather_wall_sums().
  const double dt = std::max(m_.timestep(), 1e-15);
  return rocklab::servo_velocity(kServoGain, area, wall_k_[wall], dt, target - stress,
                                 1e-3 * geo_.r_avg / dt);
}

double LoadingFrame::follow_velocity(std::size_t k) const {
  // Force-weighted mean velocity, towards the specimen (> 0 inwards), of the grains touching
  // lateral wall k. Needs gather_wall_sums().
  const auto wall = static_cast<std::size_t>(lateral_[k]);
  return wall_f_[wall] > 0 ? wall_fv_[wall] / wall_f_[wall] : 0.0;
}

void LoadingFrame::control() {
  // Confining walls hold the confinement (in every phase). Each wall follows the grains that
  // touch it (feed-forward: the force-weighted mean of their velocity along the wall normal, so a
  // dilating specimen is followed without a standing error), plus a proportional term that
  // closes the whole stress error in one step and a small integral trim (time constant 100 steps,
  // limited to 5 % of the confinement) against any remaining bias.
  if (!lateral_.empty() || phase_ == kConfine || phase_ == kSeat || reseating_)
    gather_wall_sums();
  if (servo_integral_.size() != lateral_.size())
    servo_integral_.assign(lateral_.size(), 0.0);
  for (std::size_t k = 0; k < lateral_.size(); ++k) {
    const double stress = lateral_stress_of(k);
    const double cap = 0.05 * p_.confinement * kServoIntegralSteps;
    servo_integral_[k] = std::clamp(servo_integral_[k] + p_.confinement - stress, -cap, cap);
    const double v = servo_velocity(static_cast<std::size_t>(lateral_[k]),
                                    p_.confinement + servo_integral_[k] / kServoIntegralSteps,
                                    face_area(k), stress) +
                     follow_velocity(k);
    Wall& w = m_.walls[static_cast<std::size_t>(lateral_[k])];
    if (lateral_axis_[k] < 0)
      w.radial_velocity = -v;
    else
      w.velocity = -lateral_sign_[k] * v * unit(lateral_axis_[k]);
  }
  double v = 0;
  if (phase_ == kConfine || phase_ == kSeat || (phase_ == kLoad && reseating_)) {
    const double target = phase_ == kConfine ? p_.confinement : p_.seating_stress;
    v = servo_velocity(static_cast<std::size_t>(top_), target, current_area(0),
                       current_.axial_stress);
  } else if (phase_ == kLoad) {
    // Smooth start (PFC ramps the platen velocity too): no stress wave from a sudden jolt.
    const double ramp = p_.ramp_steps > 0 ? static_cast<double>(m_.step() - ramp_start_step_) /
                                                static_cast<double>(p_.ramp_steps)
                                          : 1.0;
    v = v_final_ * smoothstep(ramp);
  } else if (phase_ == kUnload) {
    const double ramp = p_.ramp_steps > 0 ? static_cast<double>(m_.step() - reverse_step_) /
                                                static_cast<double>(p_.ramp_steps)
                                          : 1.0;
    v = v_final_ * (1 - 2 * smoothstep(ramp));
  }
  drive(v);
}

void LoadingFrame::drive(double v) {
  // The platens close (grips open) at v each [m/s].
  const Vec3 e = unit(geo_.axis);
  if (top_ >= 0) {
    m_.walls[static_cast<std::size_t>(top_)].velocity = -v * e;
    m_.walls[static_cast<std::size_t>(bottom_)].velocity = v * e;
  } else {
    for (std::int32_t i : grip_top_)
      m_.balls.vel[static_cast<std::size_t>(i)] = v * e;
    for (std::int32_t i : grip_bottom_)
      m_.balls.vel[static_cast<std::size_t>(i)] = -v * e;
  }
}

} // namespace rocklab
