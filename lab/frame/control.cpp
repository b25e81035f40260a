// Driving the frame each step: the confining walls' servo (lab/frame/confining_walls.cpp), the
// seating servo of the platens, and the platens or grips at the loading rate (smoothly ramped)
// while loading and unloading.
#include "lab/frame/loading_frame.hpp"

#include "core/servo.hpp"

#include <algorithm>

namespace rocklab {

namespace {

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

} // namespace

void LoadingFrame::control() {
  // Confining walls hold the confinement in every phase; the platens servo to their stress while
  // confining and seating, and move at the loading rate after it.
  const bool servo = phase_ == kConfine || phase_ == kSeat || (phase_ == kLoad && seating_again_);
  if (confinement_ || servo)
    wall_stiffness_sums(m_, wall_k_); // the servo gains, reused buffer
  if (confinement_)
    confinement_->control(m_, geo_, wall_height(), wall_k_);
  double v = 0;
  if (servo) {
    const double target = phase_ == kConfine ? confining_stress() : p_.seating_stress;
    v = machine_servo_velocity(m_, geo_, wall_k_[static_cast<std::size_t>(actuator_->wall())],
                               target, current_area(0), current_.axial_stress);
  } else if (phase_ == kLoad) {
    // Smooth start (PFC ramps the platen velocity too): no stress wave from a sudden jolt.
    const double ramp = p_.ramp_steps > 0 ? static_cast<double>(m_.step() - ramp_start_step_) /
                                                static_cast<double>(p_.ramp_steps)
                                          : 1.0;
    v = v_final_ * smoothstep(ramp) * approach_factor();
  } else if (phase_ == kUnload) {
    const double ramp = p_.ramp_steps > 0 ? static_cast<double>(m_.step() - reverse_step_) /
                                                static_cast<double>(p_.ramp_steps)
                                          : 1.0;
    v = v_final_ * (1 - 2 * smoothstep(ramp));
  }
  actuator_->drive(m_, geo_, v);
}

// A faster start through the seating compliance (a cushion's soft travel, the rim grains coming
// into contact), where the specimen is still elastic: approach_rate times the rate until the axial
// stress first reaches loading.approach_stress, then smoothly down to the rate.
double LoadingFrame::approach_factor() const {
  if (p_.approach_stress <= 0)
    return 1.0;
  if (approach_end_step_ < 0)
    return p_.approach_rate;
  const double x = p_.ramp_steps > 0 ? static_cast<double>(m_.step() - approach_end_step_) /
                                           static_cast<double>(p_.ramp_steps)
                                     : 1.0;
  return p_.approach_rate + (1 - p_.approach_rate) * smoothstep(x);
}

} // namespace rocklab
