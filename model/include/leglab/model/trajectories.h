#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "leglab/core/config_keys.h"
#include "leglab/model/kinematics.h"

namespace leglab {

/// The Aibo's step: 88 ticks of 8 ms = 704 ms.
inline constexpr int kStepTicks = 88;

/// The declared range of a step's length in ticks, the step test's and the walk's, as the
/// configs take it (identify.t_step_ticks, track.t_step_ticks): 32 ms to 8 s.
inline constexpr KeyDoc kStepTicksDoc{.min = 4, .max = 1000, .unit = "ticks"};
/// Any step the model's functions take (StepTestRequests, HalfEllipseLocusProblem): from the
/// fewest ticks they are defined for to a million (a finely sampled locus).
inline constexpr KeyDoc kAnyStepTicksDoc = WithRange(kStepTicksDoc, 4, 1e6);

/// The declared range of the body's pitch, nose down (PitchFootPath, desired.locus).
inline constexpr KeyDoc kBodyPitchDoc{
    .min = -45,
    .max = 45,
    .unit = "deg",
    .description =
        "the body pitched nose down; the offsets are then measured in the level "
        "ground frame and the locus turned with the body about the shoulder"};

/// One cycle of the step test of eq. 1: theta_test for t < t_step / 2, then 0.
/// Throws std::invalid_argument if t_step is outside [2, kAnyStepTicksDoc.max] (two ticks make
/// a step test's square wave).
std::vector<double> StepTestRequests(double theta_test_deg, int t_step_ticks = kStepTicks);

/// The half-elliptical foot locus of the UT Austin Villa walk (ers210a.md): a flat bottom on
/// the ground, run backward at constant speed for `ground_fraction` of the step, then a
/// half-ellipse flown forward (uniform in the ellipse's angle) for the rest.
struct HalfEllipseLocus {
  double length_mm = 48.93;                  ///< fore-aft length of the flat bottom
  double height_mm = 42.0;                   ///< height of the arc above the flat bottom
  double ground_fraction = 0.5;              ///< fraction of the step on the ground, in (0, 1)
  Eigen::Vector3d centre_mm{0.0, 0.0, 0.0};  ///< middle of the flat bottom, body frame
  int t_step_ticks = kStepTicks;             ///< ticks per step
  /// Skew of the locus in the ground plane: every point's y offset from the centre is `skew`
  /// times its x offset (mm per mm; 0 = the plain half-ellipse; the cited walk's "locus skew
  /// multiplier", 0.035). A shear: lengths along x stay the same.
  double skew = 0.0;
  /// The foot's backward speed at the swing's two ends, lift-off and touch-down, as a fraction
  /// of the stance's (length_mm / ground ticks per tick; >= 0). 0 is the plain half-ellipse,
  /// whose flight starts and ends at rest along x. Otherwise the flight's x offset is the
  /// half-ellipse's plus a cubic that is 0 at both ends and moves them backward at that speed:
  /// x(s) = -L/2 cos(pi s) - f L (n / g) (s - 3 s^2 + 2 s^3), s in [0, 1] over the n flight
  /// ticks, g the ground ticks; z is the half-ellipse's. With 1 the foot leaves the ground and
  /// meets it again moving backward with the stance (a belt under it): x is continuous in
  /// position and speed around the whole step, at the price of overshooting the flat bottom by
  /// about 0.048 L at each end (at 0.30 of the arc's height; ground fraction 0.5).
  double swing_end_speed_fraction = 0.0;
  /// A slow lift-off, for a foot that must hand its load over gently (the single-leg stand,
  /// where the carriage sinks onto the rail's stop as the foot rises): with a height d > 0 the
  /// flight's first `liftoff_ramp_ticks` (m) ticks rise from the ground along a straight line,
  /// d / m mm per tick, instead of the half-ellipse's H pi / n, and the arc is the
  /// half-ellipse's z squeezed into the rest of the flight; z is the larger of the two on the
  /// arc's way up: z(s) = max(H sin(pi u), d s / a) for u <= 1/2, H sin(pi u) after, with u =
  /// clamp((s - a) / (1 - a), 0, 1), a = m / n, s in [0, 1] over the n flight ticks. The line
  /// must stay under the arc's top (d (1 + a) / (2 a) <= H), so the arc overtakes it once and z
  /// is continuous. x is unchanged. 0 (the default): no ramp, the same bits.
  double liftoff_ramp_mm = 0.0;
  /// The ramp's length in ticks (>= 1 with a ramp, shorter than the flight).
  int liftoff_ramp_ticks = 0;
};

/// The declared range of the slow lift-off's length (HalfEllipseLocus::liftoff_ramp_ticks);
/// with a ramp it runs from 1 tick to the flight's length less one.
inline constexpr KeyDoc kLiftoffRampTicksDoc{
    .min = 0,
    .max = 100,
    .unit = "ticks",
    .description =
        "the slow lift-off's length; >= 1 with a ramp, shorter than the flight "
        "(track_stand.yaml ships 5)"};

/// The locus's shape keys with their ranges (not centre_mm, which a config derives, nor
/// t_step_ticks, which belongs to the walk: kStepTicksDoc), for desired.locus and
/// HalfEllipseLocusProblem.
void VisitKeys(KeyVisitor& visitor, HalfEllipseLocus& locus);

/// Empty when the locus is valid (its keys keep VisitKeys, t_step_ticks kAnyStepTicksDoc, a
/// finite centre and a lift-off ramp that fits the flight); otherwise what is wrong, naming
/// the field ("ground_fraction must be in (0, 1), got 1").
std::string HalfEllipseLocusProblem(const HalfEllipseLocus& locus);

/// One step of foot positions (body frame, mm), t = 0..t_step-1; t = 0 is the front end of the
/// flat bottom (touch-down). Throws std::invalid_argument naming a bad locus parameter.
std::vector<Eigen::Vector3d> HalfEllipseFootPath(const HalfEllipseLocus& locus);

/// `foot_path_mm` turned into the frame of a body pitched by `pitch_deg` (positive: nose down,
/// the front lower than the rear) about the body's y axis through `pivot_mm`: each point p,
/// placed in a level frame whose origin is `pivot_mm`, becomes pivot + Ry(-pitch) (p - pivot)
/// in the body frame (Ry: the right-handed turn about +y). E.g. with pitch 30 deg a point 100
/// mm straight below the pivot in the level frame lies at (+50, 0, -86.6) mm from it in the
/// body frame: what is below a nose-down body is ahead of its shoulder. Pitch 0 returns the
/// path unchanged (bit for bit). Throws std::invalid_argument unless pitch is finite and in
/// [-90, 90] deg.
std::vector<Eigen::Vector3d> PitchFootPath(const std::vector<Eigen::Vector3d>& foot_path_mm,
                                           const Eigen::Vector3d& pivot_mm, double pitch_deg);

/// Joint angles (rows: ticks; columns: rotator, abductor, knee), degrees, that put the foot on
/// `foot_path_mm` by closed-form inverse kinematics. Throws std::domain_error naming the tick
/// and the point when one is unreachable.
std::vector<Eigen::Vector3d> JointTrajectoryDeg(const LegGeometry& geometry,
                                                const std::vector<Eigen::Vector3d>& foot_path_mm);

}  // namespace leglab
