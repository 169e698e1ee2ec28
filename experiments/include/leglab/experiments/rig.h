#pragma once

#include <array>
#include <string>
#include <vector>

#include "leglab/controller/controller.h"
#include "leglab/experiments/config.h"
#include "leglab/model/identification.h"
#include "leglab/model/kinematics.h"
#include "leglab/sim/leg_sim.h"

namespace leglab::experiments {

/// Joint names in LegAngles order.
inline constexpr std::array<const char*, kLegJoints> kJointNames = {"rotator", "abductor", "knee"};

/// Builds the simulated leg; a missing or malformed URDF (or a missing joint or link in it) is
/// reported as InputError naming the file or item.
sim::LegSim MakePlant(const sim::SimConfig& config);

/// One step-test recording of one joint (the data of the paper's figures 3 and 4).
struct StepTestRun {
  int joint = 0;
  double theta_test_deg = 0.0;
  JointRecording recording;  ///< requests as the servo took them (clamped) and measured angles
};

/// Runs the square wave of eq. 1 (0 and theta_test alternating every half step, added to the
/// joint's hold angle) on `joint` with the other joints held still: settle_cycles cycles to
/// reach equilibrium, then record_cycles cycles recorded.
StepTestRun RunStepTest(const sim::SimConfig& sim_config, const IdentifyConfig& identify, int joint,
                        double theta_test_deg);

/// The model identified for one joint, with the recordings it was fitted to.
struct JointIdentification {
  IdentificationResult fit;
  std::vector<StepTestRun> runs;
};

/// Step tests and identification of every joint (joints in parallel, deterministic).
std::array<JointIdentification, kLegJoints> IdentifyLeg(const ExperimentConfig& config);

/// `identify`'s outputs into `out`: table1.json, table1.md and step_<joint>_<theta>.csv.
/// Returns the Markdown table (also printed by the program).
std::string WriteTable1(const std::array<JointIdentification, kLegJoints>& joints,
                        const ExperimentConfig& config, const class OutputDir& out);

}  // namespace leglab::experiments

namespace leglab::experiments {

/// One cycle of desired joint angles and the foot path it draws (body frame, mm).
struct DesiredMotion {
  DesiredCycle angles_deg;
  std::vector<Eigen::Vector3d> foot_mm;
};

/// The desired cycle: `desired.csv` when given (columns tick,rotator_deg,abductor_deg,knee_deg,
/// t = 0..T-1, one row a tick, angles within the joint limits), else the half-elliptical locus
/// through closed-form inverse kinematics. Throws InputError naming the file, row and column,
/// or the unreachable tick and point.
DesiredMotion LoadDesiredMotion(const TrackConfig& track, const LegGeometry& geometry);

/// What one run of a controller on the leg recorded over the measured steps.
struct TrackingRun {
  std::vector<LegAngles> request_deg;   ///< steps * T ticks, as the servos took them
  std::vector<LegAngles> measured_deg;  ///< the angles measured right after each request
};

/// Runs `controller` on a fresh plant that starts at rest at the desired cycle's first pose:
/// `warmup_steps` steps, then `steps` steps recorded.
TrackingRun RunTracking(const sim::SimConfig& sim_config, JointController& controller,
                        const DesiredCycle& desired, int warmup_steps, int steps);

/// Euclidean foot error per tick (cm) of a run against the desired foot path, by forward
/// kinematics of the measured angles.
std::vector<double> FootErrorsCm(const TrackingRun& run, const DesiredMotion& desired,
                                 const LegGeometry& geometry);

}  // namespace leglab::experiments
