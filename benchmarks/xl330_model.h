#pragma once
// The XL330's models as identify fits them on experiments/configs/identify_logs.yaml
// (log_fit.json's models.*.xl330), written here so that the benchmarks need no fit.

#include "leglab/model/joint_model.h"
#include "leglab/servo/servo_model.h"

namespace leglab::benchmarks {

inline constexpr double kXl330TickS = 0.005292177200317383;
inline constexpr ServoModelParams kXl330Extended{.gain_per_deg_kp = 6.164324274979596e-05,
                                                 .v_max_deg_s = 856.3316406008295,
                                                 .stall_torque_nm = 0.504851487618676,
                                                 .friction_duty = 2.3869350476813286e-14,
                                                 .friction_load_ratio = 0.37634236423778544,
                                                 .velocity_lag_s = 0.14366047744528795,
                                                 .lag_ticks = 1};
inline constexpr JointModelParams kXl330Paper{.v_max_deg_per_tick = 2.99219136623082,
                                              .theta0_deg = 1202.7878161114627,
                                              .lag_ticks = 0,
                                              .accel_ticks = 1};

}  // namespace leglab::benchmarks
