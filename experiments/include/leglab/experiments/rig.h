#pragma once

#include <array>
#include <string>
#include <vector>

#include "leglab/controller/controller.h"
#include "leglab/experiments/config.h"
#include "leglab/model/identification.h"
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

/// Step tests and identification of every joint.
std::array<JointIdentification, kLegJoints> IdentifyLeg(const ExperimentConfig& config);

/// `identify`'s outputs into `out`: table1.json, table1.md and step_<joint>_<theta>.csv.
/// Returns the Markdown table (also printed by the program).
std::string WriteTable1(const std::array<JointIdentification, kLegJoints>& joints,
                        const ExperimentConfig& config, const class OutputDir& out);

}  // namespace leglab::experiments
