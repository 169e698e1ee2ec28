#pragma once

#include <cstdint>
#include <random>

#include "leglab/sim/sim_config.h"

namespace leglab::sim {

/// The joint angle sensors: each reading is the true angle plus Gaussian noise, quantised to
/// one microradian like OPEN-R's sensor values. Draws come from std::mt19937_64 through a
/// Box-Muller transform written here (std::normal_distribution's algorithm differs between
/// standard libraries), so a seed gives the same readings everywhere.
class AngleSensor {
 public:
  /// Resolution of a reading, rad (OPEN-R reports joint angles in microradians).
  static constexpr double kQuantumRad = 1e-6;

  /// `noise_deg` (>= 0): standard deviation of the noise, degrees.
  AngleSensor(double noise_deg, std::uint64_t seed);

  /// One reading of every joint, rad, from the true angles `true_rad`, rad. Draws one normal
  /// variate per joint, in LegAngles order.
  LegAngles Measure(const LegAngles& true_rad);

  /// Changes the noise's standard deviation, deg (>= 0); the stream of draws carries on.
  void set_noise_deg(double noise_deg);

  /// One standard normal variate (mean 0, variance 1).
  double StandardNormal();

 private:
  double noise_rad_;
  std::mt19937_64 engine_;
  // Box-Muller yields variates in pairs; the second waits here.
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace leglab::sim
