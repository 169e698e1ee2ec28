#include "leglab/experiments/rig.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "leglab/app/parallel.h"
#include "leglab/app/progress.h"
#include "leglab/core/config_keys.h"
#include "leglab/core/format.h"
#include "leglab/core/units.h"
#include "leglab/experiments/trajectory_csv.h"
#include "leglab/model/joint_model_plant.h"
#include "leglab/model/metrics.h"
#include "leglab/model/trajectories.h"
#include "leglab/sim/leg_sim.h"

namespace leglab::experiments {

namespace {

// The settings a breakdown of the simulation hangs on, named as in robot.yaml.
std::string BreakdownSettings(const sim::SimConfig& sim) {
  const auto text = [](double v) { return FormatNumber(v, NumberStyle::kReadable); };
  const sim::ServoConfig& servo = sim.servo;
  std::string settings = "servo.max_speed_deg_s " + text(servo.max_speed_deg_s) +
                         ", servo.gain_per_s " + text(servo.gain_per_s) + ", servo.damping " +
                         text(servo.damping) + ", servo.smoothing_ms " + text(servo.smoothing_ms) +
                         ", servo.max_torque_nm " + text(servo.max_torque_nm) + ", sim.engine " +
                         std::string(sim::kPhysicsEngineNames[static_cast<size_t>(sim.engine)]) +
                         ", sim.physics_dt_ms " + text(sim.physics_dt_ms);
  return settings + (sim.stand.enabled ? ", stand on, stand.load_kg " + text(sim.stand.load_kg)
                                       : ", stand off");
}

// The simulated leg as the experiments drive it: a breakdown that its ranges let through is
// the settings' (bad input, SimBreakdownError naming them), not a bug of the program.
class SimPlant final : public Plant {
 public:
  explicit SimPlant(const sim::SimConfig& config) : sim_(config) {}

  void Reset(const LegAngles& pose_deg) override { sim_.Reset(pose_deg); }

  const PlantReading& Tick(const LegAngles& request_deg) override {
    try {
      return sim_.Tick(request_deg);
    } catch (const sim::SimError& e) {
      throw SimBreakdownError("the simulation broke down under these settings (" +
                              BreakdownSettings(sim_.config()) + "): " + e.problem() + " (tick " +
                              std::to_string(e.tick()) + " of its run)");
    }
  }

  const PlantReading& Read() const override { return sim_.Read(); }
  std::string_view name() const override { return sim_.name(); }

  // The config's bound on the top speed holds for changes made through the Plant interface
  // too (the loader checks plant_changes; a Python controller's changes come here).
  void ChangeSettings(std::span<const PlantSetting> settings) override {
    sim::SimConfig changed = sim_.config();
    for (const PlantSetting& setting : settings) {
      sim::SetSimSetting(changed, setting.key, setting.value);
    }
    sim::CheckTurnPerPhysicsStep(changed);
    sim_.ChangeSettings(settings);
  }

 private:
  sim::LegSim sim_;
};

}  // namespace

std::unique_ptr<Plant> MakePlant(const ExperimentConfig& config, const Robot& robot) {
  if (config.plant == PlantKind::kModel) {
    std::array<JointModelParams, kLegJoints> models;
    models.fill(config.plant_model);
    return std::make_unique<JointModelPlant>(models, robot.geometry.limits);
  }
  try {
    return std::make_unique<SimPlant>(config.sim);
  } catch (const std::exception& e) {
    throw InputError(std::string("robot: ") + e.what());
  }
}

long StepTestTicks(const IdentifyConfig& identify) {
  return static_cast<long>(identify.settle_cycles + identify.record_cycles) * identify.t_step_ticks;
}

StepTestRun RunStepTest(Plant& plant, const IdentifyConfig& identify, int joint,
                        double theta_test_deg) {
  plant.Reset(identify.hold_deg);
  const std::vector<double> cycle = StepTestRequests(theta_test_deg, identify.t_step_ticks);
  StepTestRun run{joint, theta_test_deg, {}};
  const long total = StepTestTicks(identify);
  const int first_recorded = identify.settle_cycles * identify.t_step_ticks;
  LegAngles request = identify.hold_deg;
  for (long t = 0; t < total; ++t) {
    request[joint] = identify.hold_deg[joint] + cycle[t % identify.t_step_ticks];
    const PlantReading& reading = plant.Tick(request);
    if (t >= first_recorded) {
      run.recording.request_deg.push_back(reading.applied_deg[joint]);
      run.recording.measured_deg.push_back(reading.measured_deg[joint]);
    }
    if ((t + 1) % identify.t_step_ticks == 0) CountProgressTicks(identify.t_step_ticks);
  }
  return run;
}

std::vector<JointRecording> StepTestsForFit(std::span<const JointRecording> recordings,
                                            const IdentifyConfig& identify, int warmup_ticks) {
  if (!identify.average_cycles) return {recordings.begin(), recordings.end()};
  std::vector<JointRecording> averaged;
  for (const JointRecording& r : recordings) {
    averaged.push_back(
        AverageCycles(r, identify.t_step_ticks, warmup_ticks, kStepTestPlayedCycles));
  }
  return averaged;
}

IdentificationResult FitStepTests(std::span<const JointRecording> recordings,
                                  const IdentifyConfig& identify) {
  const IdentificationOptions& search = identify.search;
  IdentificationResult fit = IdentifyJointModel(
      StepTestsForFit(recordings, identify, search.lag_max_ticks + search.accel_max_ticks), search);
  if (identify.average_cycles) {
    // The residual over every recorded tick, as the fit of the raw recordings reports it:
    // the averaged fit's squared error (weighted to count each recorded cycle) plus the
    // cycles' spread about their mean; over the same count of ticks, each recording's.
    double count = 0.0;
    double scatter = 0.0;
    for (const JointRecording& r : recordings) {
      count += static_cast<double>(r.request_deg.size());
      scatter += CycleScatter(r, identify.t_step_ticks);
    }
    const double rms = fit.rms_residual_deg;
    fit.rms_residual_deg = std::sqrt(rms * rms + scatter / count);
  }
  return fit;
}

namespace {

// The settings a step test's outcome hangs on, for the message of a model that failed.
std::string StepTestSettings(const ExperimentConfig& config) {
  const sim::SimConfig& sim = config.sim;
  const auto text = [](double v) { return FormatNumber(v, NumberStyle::kReadable); };
  std::string settings = config.plant == PlantKind::kModel
                             ? "plant: model"
                             : "servo: delay_ms " + text(sim.servo.delay_ms) +
                                   ", max_speed_deg_s " + text(sim.servo.max_speed_deg_s) +
                                   ", gain_per_s " + text(sim.servo.gain_per_s);
  if (sim.stand.enabled) settings += ", stand.load_kg " + text(sim.stand.load_kg);
  const IdentificationOptions& search = config.identify.search;
  return settings + "; identify: lag_range_ticks [" + std::to_string(search.lag_min_ticks) + ", " +
         std::to_string(search.lag_max_ticks) + "], accel_range_ticks [" +
         std::to_string(search.accel_min_ticks) + ", " + std::to_string(search.accel_max_ticks) +
         "]";
}

std::string StepHeights(const IdentifyConfig& identify) {
  std::string text;
  for (size_t i = 0; i < identify.theta_test_deg.size(); ++i) {
    text += (i == 0                                    ? ""
             : i + 1 == identify.theta_test_deg.size() ? " and "
                                                       : ", ") +
            FormatNumber(identify.theta_test_deg[i], NumberStyle::kReadable);
  }
  return text + " deg";
}

}  // namespace

void CheckIdentifiedModel(const ExperimentConfig& config, int joint,
                          const IdentificationResult& fit) {
  std::string problem;
  try {
    CheckKeys("model.", fit.params, [](KeyVisitor& v, JointModelParams& p) { VisitKeys(v, p); });
  } catch (const std::invalid_argument& e) {
    problem = e.what();
  }
  double smallest_step = std::numeric_limits<double>::infinity();
  for (const double theta : config.identify.theta_test_deg) {
    smallest_step = std::min(smallest_step, std::abs(theta));
  }
  if (problem.empty() && !(fit.rms_residual_deg <= kFailedFitResidualFraction * smallest_step)) {
    problem = "its RMS residual " + FormatNumber(fit.rms_residual_deg, NumberStyle::kReadable) +
              " deg is over a quarter of the smallest step";
  }
  if (problem.empty()) return;
  throw InputError("joint '" + std::string(kLegJointNames[joint]) + "': its step tests of " +
                   StepHeights(config.identify) + " fit no joint model: " + problem + " (" +
                   StepTestSettings(config) + ")");
}

std::array<JointIdentification, kLegJoints> IdentifyLeg(const ExperimentConfig& config,
                                                        const Robot& robot) {
  // Build one plant first so that bad robot input fails before any thread starts.
  MakePlant(config, robot);
  SetProgressPhase("step tests and identification");
  // Each joint with its own plants: the result does not depend on the schedule.
  std::array<JointIdentification, kLegJoints> joints;
  ParallelFor(kLegJoints, config.threads, [&](int joint) {
    JointIdentification& result = joints[joint];
    std::vector<JointRecording> recordings;
    for (double theta : config.identify.theta_test_deg) {
      const std::unique_ptr<Plant> plant = MakePlant(config, robot);
      result.runs.push_back(RunStepTest(*plant, config.identify, joint, theta));
      recordings.push_back(result.runs.back().recording);
    }
    result.fit = FitStepTests(recordings, config.identify);
  });
  // In joint order, after every fit: the error names the same joint whatever the schedule.
  for (int joint = 0; joint < kLegJoints; ++joint)
    CheckIdentifiedModel(config, joint, joints[joint].fit);
  return joints;
}

Eigen::Vector3d FootMm(const LegGeometry& geometry, const LegAngles& q_deg) {
  return ForwardKinematics(
      geometry, Eigen::Vector3d(DegToRad(q_deg[0]), DegToRad(q_deg[1]), DegToRad(q_deg[2])));
}

DesiredMotion LoadDesiredMotion(const TrackConfig& track, const LegGeometry& geometry) {
  if (!track.desired_csv.empty()) {
    DesiredMotion d;
    d.angles_deg = ReadDesiredCsv(track.desired_csv, track.t_step_ticks, geometry.limits);
    for (const LegAngles& q : d.angles_deg) d.foot_mm.push_back(FootMm(geometry, q));
    return d;
  }
  HalfEllipseLocus locus = track.locus.shape;
  locus.t_step_ticks = track.t_step_ticks;
  locus.centre_mm =
      geometry.shoulder_mm + Eigen::Vector3d(track.locus.forward_mm,
                                             geometry.OutwardSign() * track.locus.outward_mm,
                                             -track.locus.ground_below_shoulder_mm);
  // Outward is +y on a left leg, -y on a right one.
  locus.skew = geometry.OutwardSign() * track.locus.shape.skew;
  DesiredMotion d;
  d.foot_mm =
      PitchFootPath(HalfEllipseFootPath(locus), geometry.shoulder_mm, track.locus.body_pitch_deg);
  try {
    for (const Eigen::Vector3d& q : JointTrajectoryDeg(geometry, d.foot_mm)) {
      d.angles_deg.push_back({q[0], q[1], q[2]});
    }
  } catch (const std::domain_error& e) {
    throw InputError(std::string("desired.locus: ") + e.what());
  }
  return d;
}

namespace {

// The tracking loop of RunTracking: `on_tick(t, reading)` sees every tick's reading, t from 0
// over warm-up and measured steps alike; `on_step_end(step)` follows each step's EndOfStep
// (steps from 0 over warm-up and measured steps). Each of `changes` is applied right before
// the first tick of its measured step.
template <typename OnTick, typename OnStepEnd>
void TrackingLoop(Plant& plant, JointController& controller, const DesiredCycle& desired,
                  int warmup_steps, int steps, std::span<const PlantChange> changes, OnTick on_tick,
                  OnStepEnd on_step_end) {
  SetProgressPhase("walking");
  plant.Reset(desired[0]);
  controller.Reset();
  const long period = static_cast<long>(desired.size());
  const long total = (warmup_steps + static_cast<long>(steps)) * period;
  LegAngles measured = plant.Read().measured_deg;
  size_t next_change = 0;
  for (long t = 0; t < total; ++t) {
    if (next_change < changes.size() &&
        t == (warmup_steps + static_cast<long>(changes[next_change].at_step)) * period) {
      plant.ChangeSettings(changes[next_change++].set);
    }
    const PlantReading& reading = plant.Tick(controller.Update(t, measured));
    controller.Observe(t, reading.applied_deg, reading.measured_deg);
    measured = reading.measured_deg;
    on_tick(t, reading);
    if ((t + 1) % period == 0) {
      controller.EndOfStep(t / period);
      on_step_end(t / period);
      CountProgressTicks(period);
    }
  }
}

}  // namespace

TrackingRun RunTracking(Plant& plant, JointController& controller, const DesiredCycle& desired,
                        int warmup_steps, int steps, std::span<const PlantChange> changes) {
  const long period = static_cast<long>(desired.size());
  const long first_recorded = warmup_steps * period;
  TrackingRun run;
  run.request_deg.reserve(steps * period);
  run.measured_deg.reserve(steps * period);
  run.telemetry.reserve(steps * period);
  TrackingLoop(
      plant, controller, desired, warmup_steps, steps, changes,
      [&](long t, const PlantReading& reading) {
        if (t >= first_recorded) {
          run.request_deg.push_back(reading.applied_deg);
          run.measured_deg.push_back(reading.measured_deg);
          run.telemetry.push_back(reading.telemetry);
        } else {
          run.warmup_measured_deg.push_back(reading.measured_deg);
          if (t + 1 == first_recorded) run.telemetry_before = reading.telemetry;
        }
      },
      [&](long step) {
        if (const std::optional<JointModelEstimates> estimates = controller.ModelEstimates()) {
          run.model_estimates.push_back({step - warmup_steps, *estimates});
        }
      });
  return run;
}

double TrackingFootL2Cm(Plant& plant, JointController& controller, const DesiredMotion& desired,
                        const LegGeometry& geometry, int warmup_steps, int steps,
                        std::span<const PlantChange> changes) {
  const long period = static_cast<long>(desired.angles_deg.size());
  const long first_recorded = warmup_steps * period;
  // The same sums in the same order as FootErrorsCm and MeanFootL2Cm: the same bits.
  std::vector<double> step_errors(period);
  std::vector<double> per_step;
  per_step.reserve(steps);
  TrackingLoop(
      plant, controller, desired.angles_deg, warmup_steps, steps, changes,
      [&](long t, const PlantReading& reading) {
        if (t < first_recorded) return;
        const long tick = (t - first_recorded) % period;
        step_errors[tick] =
            (FootMm(geometry, reading.measured_deg) - desired.foot_mm[tick]).norm() / 10.0;
        if (tick == period - 1) per_step.push_back(Rms(step_errors));
      },
      [](long /*step*/) {});
  return MeanAndStd(per_step).mean;
}

std::vector<Eigen::Vector3d> TrackingFootPathMm(Plant& plant, JointController& controller,
                                                const DesiredCycle& desired,
                                                const LegGeometry& geometry, int warmup_steps,
                                                int steps) {
  const long first_recorded = warmup_steps * static_cast<long>(desired.size());
  std::vector<Eigen::Vector3d> path;
  path.reserve(static_cast<size_t>(steps) * desired.size());
  TrackingLoop(
      plant, controller, desired, warmup_steps, steps, {},
      [&](long t, const PlantReading& reading) {
        if (t >= first_recorded) path.push_back(FootMm(geometry, reading.measured_deg));
      },
      [](long /*step*/) {});
  return path;
}

std::vector<double> FootErrorsCm(const TrackingRun& run, const DesiredMotion& desired,
                                 const LegGeometry& geometry) {
  const size_t period = desired.foot_mm.size();
  std::vector<double> errors(run.measured_deg.size());
  for (size_t t = 0; t < errors.size(); ++t) {
    errors[t] = (FootMm(geometry, run.measured_deg[t]) - desired.foot_mm[t % period]).norm() / 10.0;
  }
  return errors;
}

}  // namespace leglab::experiments
