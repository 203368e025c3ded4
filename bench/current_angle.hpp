// The current angle th_i of a window's mean current vector, and whether it agrees with the angle
// the bench requested. Without it the record's angle is only the request's: a drive that never
// received the angle (a lost write, a profile mapping the wrong register) would be measured and
// stored as if it ran at the requested angle. Pure logic.
#pragma once

#include <optional>

namespace synbench::bench {

// th_i of the mean (i_d, i_q) in degrees, in the convention of physics.md Sec. 0 and the
// firmware: i_dq = I_m [cos th_i, sin th_i] with i_d >= 0 and the torque's sign (braking) on i_q,
// so th_i = atan2(|i_q|, i_d), in [0, 180]; a motoring point lies in (0, 90). Empty for a zero
// vector, which has no angle.
std::optional<double> current_angle_deg(double id_A, double iq_A);

// The angles the bench commands: motoring, strictly between the d axis (no torque) and the q axis
// (no torque either, and all reluctance flux on the weak axis). Sweep plans, the REST setpoints
// and `synbench point --angle-deg` all hold a request to this one rule.
inline constexpr double kMotoringAngleAbove_deg = 0, kMotoringAngleBelow_deg = 90;
constexpr bool is_motoring_angle(double angle_deg) {
  return angle_deg > kMotoringAngleAbove_deg && angle_deg < kMotoringAngleBelow_deg;
}

// How far the measured angle may be from the request at a mean current vector of magnitude
// `im_A` before the point is flagged `angle_off`; empty below kAngleJudgedFrom_A (not judged).
// The current controller's integral action tracks the angle reference with no mean error, so a
// window mean differs from the request only by what the currents are measured with: a fixed
// kAngleTolerance_deg (the setpoint register's rounding, the reference still moving by a
// sensorless drive's angle slew as the window opens) plus the angle an absolute current error
// of kCurrentError_A (a drive's current sensor offset, a telemetry register's 0.01 A, ripple left
// in a host window's few polls) makes at right angles to the vector: atan(kCurrentError_A / I).
// That term grows as the current falls (14 deg at 0.2 A); below the floor the error could be of
// any size and the mean vector of a nearly unloaded machine says nothing about the reference.
inline constexpr double kAngleTolerance_deg = 2.0;
inline constexpr double kCurrentError_A = 0.05;
inline constexpr double kAngleJudgedFrom_A = 0.2;  // ~10 % of the SynRM's 2.26 A rated peak
std::optional<double> angle_tolerance_deg(double im_A);

// The measured angle differs from the request by more than angle_tolerance_deg(|i_dq|): a
// warning in the record (`angle_off`), never a refused point, since the window's powers are true
// for the angle the machine ran at (stored as `angle_meas_deg`), and at the voltage limit the
// controller cannot hold the reference by physics (the point is then also `voltage_limited`).
bool angle_off(double request_deg, double id_A, double iq_A);

}  // namespace synbench::bench
