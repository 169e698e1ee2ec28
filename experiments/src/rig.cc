#include "leglab/experiments/rig.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <future>
#include <sstream>

#include "leglab/experiments/output.h"
#include "leglab/model/joint_model.h"
#include "leglab/model/trajectories.h"

namespace leglab::experiments {

sim::LegSim MakePlant(const sim::SimConfig& config) {
  try {
    return sim::LegSim(config);
  } catch (const sim::SimError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(std::string("robot: ") + e.what());
  }
}

StepTestRun RunStepTest(const sim::SimConfig& sim_config, const IdentifyConfig& identify, int joint,
                        double theta_test_deg) {
  sim::LegSim plant = MakePlant(sim_config);
  plant.SetJointAnglesDeg(identify.hold_deg);
  const std::vector<double> cycle = StepTestRequests(theta_test_deg, identify.t_step_ticks);
  StepTestRun run{joint, theta_test_deg, {}};
  const int total = (identify.settle_cycles + identify.record_cycles) * identify.t_step_ticks;
  const int first_recorded = identify.settle_cycles * identify.t_step_ticks;
  LegAngles request = identify.hold_deg;
  for (int t = 0; t < total; ++t) {
    request[joint] = identify.hold_deg[joint] + cycle[t % identify.t_step_ticks];
    plant.SetRequestsDeg(request);
    plant.Tick();
    if (t >= first_recorded) {
      run.recording.request_deg.push_back(plant.CommandedDeg()[joint]);
      run.recording.measured_deg.push_back(plant.MeasuredDeg()[joint]);
    }
  }
  return run;
}

std::array<JointIdentification, kLegJoints> IdentifyLeg(const ExperimentConfig& config) {
  // Build one plant first so that bad robot input fails before any thread starts.
  MakePlant(config.sim);
  auto identify_joint = [&config](int joint) {
    JointIdentification result;
    std::vector<JointRecording> recordings;
    for (double theta : config.identify.theta_test_deg) {
      result.runs.push_back(RunStepTest(config.sim, config.identify, joint, theta));
      recordings.push_back(result.runs.back().recording);
    }
    result.fit = IdentifyJointModel(recordings, config.identify.search);
    return result;
  };
  // Each joint on its own thread, with its own plants: the result does not depend on the
  // schedule.
  std::array<std::future<JointIdentification>, kLegJoints> pending;
  for (int j = 0; j < kLegJoints; ++j) {
    pending[j] = std::async(std::launch::async, identify_joint, j);
  }
  std::array<JointIdentification, kLegJoints> joints;
  for (int j = 0; j < kLegJoints; ++j) joints[j] = pending[j].get();
  return joints;
}

namespace {

std::string ThetaLabel(double theta) {
  return theta == std::round(theta) ? std::to_string(static_cast<long>(theta))
                                    : FormatDouble(theta);
}

std::string Fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

}  // namespace

std::string WriteTable1(const std::array<JointIdentification, kLegJoints>& joints,
                        const ExperimentConfig& config, const OutputDir& out) {
  const JointModelParams paper{2.5, 7.0, 4, 6};
  nlohmann::ordered_json json;
  for (int j = 0; j < kLegJoints; ++j) {
    const JointModelParams& p = joints[j].fit.params;
    json["joints"][kJointNames[j]] = {{"v_max_deg_per_tick", p.v_max_deg_per_tick},
                                      {"theta0_deg", p.theta0_deg},
                                      {"lag_ticks", p.lag_ticks},
                                      {"accel_ticks", p.accel_ticks},
                                      {"fit_rms_deg", joints[j].fit.rms_residual_deg}};
  }
  json["paper"] = {{"v_max_deg_per_tick", paper.v_max_deg_per_tick},
                   {"theta0_deg", paper.theta0_deg},
                   {"lag_ticks", paper.lag_ticks},
                   {"accel_ticks", paper.accel_ticks}};
  json["plant"] = {{"robot", config.robot_yaml},
                   {"delay_ms", config.sim.servo.delay_ms},
                   {"max_speed_deg_s", config.sim.servo.max_speed_deg_s},
                   {"gain_per_s", config.sim.servo.gain_per_s},
                   {"smoothing_ms", config.sim.servo.smoothing_ms},
                   {"max_torque_nm", config.sim.servo.max_torque_nm},
                   {"noise_deg", config.sim.sensor.noise_deg},
                   {"seed", config.sim.seed}};
  WriteTextFile(out.Path("table1.json"), json.dump(2) + '\n');

  std::ostringstream md;
  md << "# Table 1: model parameters\n\n"
     << "Identified from the simulated leg's step tests (eq. 1, theta_test";
  for (double theta : config.identify.theta_test_deg) md << ' ' << ThetaLabel(theta);
  md << " deg), beside the paper's values.\n\n"
     << "| Parameter | Description | Paper | Rotator | Abductor | Knee |\n"
     << "|---|---|---|---|---|---|\n";
  auto row = [&](const char* symbol, const char* description, const std::string& paper_value,
                 auto value_of) {
    md << "| " << symbol << " | " << description << " | " << paper_value;
    for (int j = 0; j < kLegJoints; ++j) md << " | " << value_of(joints[j]);
    md << " |\n";
  };
  row("v_max", "Maximum angular speed (deg/t_u)", "2.5",
      [](const JointIdentification& j) { return Fixed(j.fit.params.v_max_deg_per_tick, 2); });
  row("theta_0", "Angle difference threshold (deg)", "7.0",
      [](const JointIdentification& j) { return Fixed(j.fit.params.theta0_deg, 2); });
  row("l", "Lag time (t_u)", "4",
      [](const JointIdentification& j) { return std::to_string(j.fit.params.lag_ticks); });
  row("a", "Acceleration time (t_u)", "6",
      [](const JointIdentification& j) { return std::to_string(j.fit.params.accel_ticks); });
  row("", "Fit RMS residual (deg)", "",
      [](const JointIdentification& j) { return Fixed(j.fit.rms_residual_deg, 3); });
  md << "\nt_u = 8 ms.\n";
  WriteTextFile(out.Path("table1.md"), md.str());

  for (const JointIdentification& joint : joints) {
    for (const StepTestRun& run : joint.runs) {
      const auto& r = run.recording;
      const int period = config.identify.t_step_ticks;
      // The identified model's prediction: its cyclic steady state under the request cycle.
      const std::vector<double> cycle(r.request_deg.begin(), r.request_deg.begin() + period);
      const std::vector<double> model = CyclicSteadyState(joint.fit.params, cycle);
      CsvWriter csv(out.Path(std::string("step_") + kJointNames[run.joint] + "_" +
                             ThetaLabel(run.theta_test_deg) + ".csv"),
                    {"tick", "request_deg", "actual_deg", "model_deg"});
      for (size_t t = 0; t < r.request_deg.size(); ++t) {
        csv.Cell(static_cast<long>(t))
            .Cell(r.request_deg[t])
            .Cell(r.measured_deg[t])
            .Cell(model[t % period]);
        csv.EndRow();
      }
      csv.Close();
    }
  }
  return md.str();
}

}  // namespace leglab::experiments

namespace leglab::experiments {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

DesiredMotion DesiredFromCsv(const std::string& path, int period, const LegGeometry& geometry) {
  std::ifstream in(path);
  if (!in) throw InputError("desired.csv: cannot read '" + path + "'");
  auto fail = [&](const std::string& what) {
    throw InputError("desired.csv '" + path + "': " + what);
  };
  std::string line;
  if (!std::getline(in, line)) fail("is empty");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != "tick,rotator_deg,abductor_deg,knee_deg") {
    fail("header must be 'tick,rotator_deg,abductor_deg,knee_deg', got '" + line + "'");
  }
  DesiredMotion d;
  for (int row = 1; std::getline(in, line); ++row) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
    if (cells.size() != 4)
      fail("row " + std::to_string(row) + " has " + std::to_string(cells.size()) +
           " columns, expected 4");
    double values[4];
    for (int c = 0; c < 4; ++c) {
      const char* names[4] = {"tick", "rotator_deg", "abductor_deg", "knee_deg"};
      try {
        size_t used = 0;
        values[c] = std::stod(cells[c], &used);
        if (used != cells[c].size()) throw std::invalid_argument("trailing text");
      } catch (const std::exception&) {
        fail("row " + std::to_string(row) + ", " + names[c] + ": '" + cells[c] +
             "' is not a number");
      }
      if (!std::isfinite(values[c]))
        fail("row " + std::to_string(row) + ", " + names[c] + " is not finite");
      if (c > 0) {
        const JointLimits& lim = geometry.limits[c - 1];
        if (values[c] * kDegToRad < lim.lower_rad - 1e-9 ||
            values[c] * kDegToRad > lim.upper_rad + 1e-9) {
          fail("row " + std::to_string(row) + ", " + names[c] + " = " + cells[c] +
               " is outside the joint limits");
        }
      }
    }
    if (values[0] != static_cast<double>(d.angles_deg.size())) {
      fail("row " + std::to_string(row) + ": tick must be " + std::to_string(d.angles_deg.size()) +
           ", got " + cells[0]);
    }
    d.angles_deg.push_back({values[1], values[2], values[3]});
  }
  if (static_cast<int>(d.angles_deg.size()) != period) {
    fail("has " + std::to_string(d.angles_deg.size()) +
         " rows, expected one cycle of track.t_step_ticks = " + std::to_string(period));
  }
  for (const LegAngles& q : d.angles_deg) {
    d.foot_mm.push_back(ForwardKinematics(geometry, Eigen::Vector3d(q[0], q[1], q[2]) * kDegToRad));
  }
  return d;
}

}  // namespace

DesiredMotion LoadDesiredMotion(const TrackConfig& track, const LegGeometry& geometry) {
  if (!track.desired_csv.empty())
    return DesiredFromCsv(track.desired_csv, track.t_step_ticks, geometry);
  HalfEllipseLocus locus;
  locus.length_mm = track.locus.length_mm;
  locus.height_mm = track.locus.height_mm;
  locus.ground_fraction = track.locus.ground_fraction;
  locus.t_step_ticks = track.t_step_ticks;
  locus.centre_mm =
      geometry.shoulder_mm + Eigen::Vector3d(track.locus.forward_mm, track.locus.outward_mm,
                                             -track.locus.ground_below_shoulder_mm);
  DesiredMotion d;
  d.foot_mm = HalfEllipseFootPath(locus);
  try {
    for (const Eigen::Vector3d& q : JointTrajectoryDeg(geometry, d.foot_mm))
      d.angles_deg.push_back({q[0], q[1], q[2]});
  } catch (const std::domain_error& e) {
    throw InputError(std::string("desired.locus: ") + e.what());
  }
  return d;
}

TrackingRun RunTracking(const sim::SimConfig& sim_config, JointController& controller,
                        const DesiredCycle& desired, int warmup_steps, int steps) {
  sim::LegSim plant = MakePlant(sim_config);
  plant.SetJointAnglesDeg(desired[0]);
  const long period = static_cast<long>(desired.size());
  const long first_recorded = warmup_steps * period;
  const long total = first_recorded + steps * period;
  TrackingRun run;
  run.request_deg.reserve(steps * period);
  run.measured_deg.reserve(steps * period);
  LegAngles measured = plant.MeasuredDeg();
  for (long t = 0; t < total; ++t) {
    plant.SetRequestsDeg(controller.Update(t, measured));
    plant.Tick();
    measured = plant.MeasuredDeg();
    if (t >= first_recorded) {
      run.request_deg.push_back(plant.CommandedDeg());
      run.measured_deg.push_back(measured);
    }
  }
  return run;
}

std::vector<double> FootErrorsCm(const TrackingRun& run, const DesiredMotion& desired,
                                 const LegGeometry& geometry) {
  const size_t period = desired.foot_mm.size();
  std::vector<double> errors(run.measured_deg.size());
  for (size_t t = 0; t < errors.size(); ++t) {
    const LegAngles& q = run.measured_deg[t];
    const Eigen::Vector3d foot =
        ForwardKinematics(geometry, Eigen::Vector3d(q[0], q[1], q[2]) * kDegToRad);
    errors[t] = (foot - desired.foot_mm[t % period]).norm() / 10.0;
  }
  return errors;
}

}  // namespace leglab::experiments
