#pragma once

#include <array>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "leglab/controller/controller.h"
#include "leglab/core/plant.h"
#include "leglab/experiments/config.h"
#include "leglab/experiments/robot.h"
#include "leglab/model/identification.h"
#include "leglab/model/kinematics.h"

namespace leglab::experiments {

/// Bad input of one kind: settings, each inside its range, under which the simulated leg
/// broke down during a run (sim::SimError from its state check: a link's state non-finite, a
/// joint spinning or coming apart). The message is one line: "the simulation broke down under
/// these settings (<servo.*, sim.physics_dt_ms and stand values>): <what broke> (tick <t> of
/// its run)".
class SimBreakdownError : public InputError {
 public:
  using InputError::InputError;
};

/// A fresh plant of the kind the config names (`plant: sim` or `model`), at rest at q = 0 (or
/// the pose nearest it inside the limits). Bad robot input (a missing or malformed URDF, a
/// bad servo value) is reported as InputError naming the file or key. The simulated leg's
/// Tick() throws SimBreakdownError, naming its settings of the moment (after any
/// ChangeSettings), where sim::LegSim throws sim::SimError.
std::unique_ptr<Plant> MakePlant(const ExperimentConfig& config, const Robot& robot);

/// One step-test recording of one joint (the data of the paper's figures 3 and 4).
struct StepTestRun {
  int joint = 0;
  double theta_test_deg = 0.0;
  JointRecording recording;  ///< requests as the servo took them (clamped) and measured angles
};

/// Runs the square wave of eq. 1 (0 and theta_test alternating every half step, added to the
/// joint's hold angle) on `joint` of `plant` with the other joints held still: settle_cycles
/// cycles to reach equilibrium, then record_cycles cycles recorded.
StepTestRun RunStepTest(Plant& plant, const IdentifyConfig& identify, int joint,
                        double theta_test_deg);

/// Plant ticks of one step test (settle and record cycles of t_step_ticks).
long StepTestTicks(const IdentifyConfig& identify);

/// With identify.average_cycles, the fit takes each step test's recorded cycles averaged into
/// one (synchronous averaging, AverageCycles: the requests repeat every cycle and the plant is
/// time-invariant, so the cycles differ only by the sensor noise) and scores the model's
/// prediction over this many plays of it after the fit's warm-up: the least-squares objective
/// of every recorded tick up to a constant and the model's start-up, for 1/4 of the ticks at 8
/// recorded cycles. The walk fit averages its walk the same way (kWalkFitPlayedCycles).
inline constexpr int kStepTestPlayedCycles = 2;

/// The step tests' `recordings` as a fit with warm-up `warmup_ticks` takes them: averaged (see
/// kStepTestPlayedCycles) with identify.average_cycles, else as they are.
std::vector<JointRecording> StepTestsForFit(std::span<const JointRecording> recordings,
                                            const IdentifyConfig& identify, int warmup_ticks);

/// Fits the paper's model to one joint's step-test recordings as `identify` does:
/// StepTestsForFit (warm-up lag_max + accel_max), IdentifyJointModel over identify.search, and
/// with identify.average_cycles the residual over every recorded tick (the averaged fit's plus
/// the cycles' spread about their mean, CycleScatter). Throws std::invalid_argument as
/// IdentifyJointModel and AverageCycles do.
IdentificationResult FitStepTests(std::span<const JointRecording> recordings,
                                  const IdentifyConfig& identify);

/// The model identified for one joint, with the recordings it was fitted to.
struct JointIdentification {
  IdentificationResult fit;
  std::vector<StepTestRun> runs;
};

/// A fit whose RMS residual is over this fraction of the smallest step height
/// (identify.theta_test_deg) has failed: a model that fits follows its steps to a few percent.
inline constexpr double kFailedFitResidualFraction = 0.25;

/// Throws InputError naming the joint, the step heights and the servo's settings when the model
/// fitted to joint `joint`'s step tests is outside the model's own ranges (model.*) or its
/// residual says the fit failed (kFailedFitResidualFraction): a plant no model of eq. 3 fits,
/// not a table to print.
void CheckIdentifiedModel(const ExperimentConfig& config, int joint,
                          const IdentificationResult& fit);

/// Step tests (each on a fresh plant) and identification of every joint, joints in parallel
/// on config.threads threads (the result does not depend on the count). Each model is checked
/// (CheckIdentifiedModel).
std::array<JointIdentification, kLegJoints> IdentifyLeg(const ExperimentConfig& config,
                                                        const Robot& robot);

/// One cycle of desired joint angles and the foot path it draws (body frame, mm).
struct DesiredMotion {
  DesiredCycle angles_deg;
  std::vector<Eigen::Vector3d> foot_mm;
};

/// The desired cycle: `desired.csv` when given (ReadDesiredCsv: columns
/// tick,rotator_deg,abductor_deg,knee_deg, t = 0..T-1, one row a tick, angles within the joint
/// limits; the foot path by forward kinematics), else the half-elliptical locus
/// placed relative to the leg's shoulder (outward meaning away from the body, whichever side
/// the leg is on) through closed-form inverse kinematics. Throws InputError naming the file,
/// row and column, or the unreachable tick and point.
DesiredMotion LoadDesiredMotion(const TrackConfig& track, const LegGeometry& geometry);

/// A controller's model estimates at the end of one step (JointController::ModelEstimates).
struct StepModelEstimates {
  long step = 0;  ///< warm-up steps negative, measured steps from 0
  JointModelEstimates joints;
};

/// What one run of a controller on a plant recorded over the measured steps.
struct TrackingRun {
  std::vector<LegAngles> request_deg;          ///< steps * T ticks, as the servos applied them
  std::vector<LegAngles> measured_deg;         ///< the angles measured right after each request
  std::vector<LegAngles> warmup_measured_deg;  ///< warmup_steps * T ticks before those
  /// The plant's telemetry (the stand's instruments) at each measured tick, steps * T; the
  /// controller never sees it. Zeros for a plant without a stand.
  std::vector<PlantTelemetry> telemetry;
  /// The telemetry at the end of the warm-up (or of the reset, without one): the slip count
  /// the first measured step starts from.
  PlantTelemetry telemetry_before{};
  /// After every step (warm-up included), for a controller that estimates the model; else
  /// empty.
  std::vector<StepModelEstimates> model_estimates;
};

/// Runs `controller` (Reset first) on `plant` from rest at the desired cycle's first pose:
/// `warmup_steps` steps, then `steps` steps recorded. Calls the controller's Update, Observe
/// and EndOfStep hooks as JointController documents, and records its ModelEstimates after
/// every step. Each of `changes` (by increasing at_step) is applied to the plant
/// (Plant::ChangeSettings) right before the first tick of measured step at_step.
TrackingRun RunTracking(Plant& plant, JointController& controller, const DesiredCycle& desired,
                        int warmup_steps, int steps, std::span<const PlantChange> changes = {});

/// What RunTracking then MeanFootL2Cm of FootErrorsCm would give, bit for bit (the mean over
/// the measured steps of each step's RMS foot error, cm), without keeping the run: memory
/// O(period + steps) instead of O(steps x period). For scoring search candidates.
double TrackingFootL2Cm(Plant& plant, JointController& controller, const DesiredMotion& desired,
                        const LegGeometry& geometry, int warmup_steps, int steps,
                        std::span<const PlantChange> changes = {});

/// The measured foot path (body frame, mm, by forward kinematics) over the measured steps of
/// what RunTracking would run, without keeping the run: steps x period points.
std::vector<Eigen::Vector3d> TrackingFootPathMm(Plant& plant, JointController& controller,
                                                const DesiredCycle& desired,
                                                const LegGeometry& geometry, int warmup_steps,
                                                int steps);

/// Foot position (body frame, mm) for joint angles in degrees.
Eigen::Vector3d FootMm(const LegGeometry& geometry, const LegAngles& q_deg);

/// Euclidean foot error per tick (cm) of a run against the desired foot path, by forward
/// kinematics of the measured angles.
std::vector<double> FootErrorsCm(const TrackingRun& run, const DesiredMotion& desired,
                                 const LegGeometry& geometry);

}  // namespace leglab::experiments
