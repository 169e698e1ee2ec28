#include "leglab/sim/angle_sensor.h"
#include "leglab/core/units.h"

#include <cmath>
#include <numbers>

namespace leglab::sim {

AngleSensor::AngleSensor(double noise_deg, std::uint64_t seed)
    : noise_rad_(DegToRad(noise_deg)), engine_(seed) {}

void AngleSensor::set_noise_deg(double noise_deg) { noise_rad_ = DegToRad(noise_deg); }

double AngleSensor::StandardNormal() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  // Uniform doubles from the top 53 bits; 1 - u lies in (0, 1], so the log is finite.
  constexpr double kTwoToMinus53 = 0x1.0p-53;
  const double u1 = 1.0 - static_cast<double>(engine_() >> 11) * kTwoToMinus53;
  const double u2 = static_cast<double>(engine_() >> 11) * kTwoToMinus53;
  const double radius = std::sqrt(-2.0 * std::log(u1));
  const double phase = 2.0 * std::numbers::pi * u2;
  spare_ = radius * std::sin(phase);
  has_spare_ = true;
  return radius * std::cos(phase);
}

LegAngles AngleSensor::Measure(const LegAngles& true_rad) {
  LegAngles reading{};
  for (int j = 0; j < kLegJoints; ++j) {
    const double noisy = true_rad[j] + noise_rad_ * StandardNormal();
    reading[j] = std::round(noisy / kQuantumRad) * kQuantumRad;
  }
  return reading;
}

}  // namespace leglab::sim
