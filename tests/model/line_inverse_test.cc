#include "leglab/model/line_inverse.h"
#include "leglab/model/paper.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace leglab {
namespace {

constexpr JointModelParams kPaper = paper::kTable1;

// Brute force: request the ramp L(t) = m t for a long time and read off L - M at the end.
double RampOffsetByBruteForce(const JointModelParams& p, double m, int ticks = 4000) {
  std::vector<double> ramp(ticks);
  for (int t = 0; t < ticks; ++t) ramp[t] = m * t;
  const std::vector<double> angles = SimulateJointModel(p, ramp, RestState(p, 0.0));
  return ramp.back() - angles.back();
}

// In f's linear regime every term of the average is (x - m j) v/theta_0, j = l .. l+a-1:
//   exact (sum):      S(C) = v/theta_0 (C - m (l + (a - 1)/2)) = m  =>  C = m (theta_0/v + l +
//   (a-1)/2) closed (integral): (1/a) int_l^{l+a} ... = v/theta_0 (C - m (l + a/2)) = m   (eq. 11)
// For Table 1 and m = 0.5: exact 0.5 (2.8 + 4 + 2.5) = 4.65, closed 0.5 (2.8 + 4 + 3) = 4.9.
TEST(LineInverse, LinearRegimeByHand) {
  EXPECT_NEAR(LineInverseOffsetExact(kPaper, 0.5), 4.65, 1e-12);
  EXPECT_NEAR(LineInverseOffsetClosed(kPaper, 0.5), 4.9, 1e-12);
  EXPECT_NEAR(LineInverseOffsetExact(kPaper, 1.0), 9.3, 1e-12);
  EXPECT_NEAR(LineInverseOffsetClosed(kPaper, 1.0), 9.8, 1e-12);
  // The integral shifts every sample by half a tick: the two differ by m / 2 here.
  for (double m : {0.1, 0.3, 0.7, 1.1}) {
    EXPECT_NEAR(LineInverseOffsetClosed(kPaper, m) - LineInverseOffsetExact(kPaper, m), m / 2.0,
                1e-12)
        << "m = " << m;
  }
}

TEST(LineInverse, ExactAgreesWithBruteForceRamp) {
  for (double m : {0.05, 0.5, 1.0, 1.2, 1.5, 1.9, 2.2, 2.45, -0.8, -2.3}) {
    EXPECT_NEAR(LineInverseOffsetExact(kPaper, m), RampOffsetByBruteForce(kPaper, m), 1e-9)
        << "m = " << m;
  }
  // Other parameters, including ones outside eq. 13 where only the exact form applies.
  for (const JointModelParams& p :
       {JointModelParams{3.0, 5.0, 2, 9}, JointModelParams{2.0, 1.5, 0, 3},
        JointModelParams{1.0, 8.0, 7, 1}}) {
    for (double m :
         {0.2 * p.v_max_deg_per_tick, 0.6 * p.v_max_deg_per_tick, -0.95 * p.v_max_deg_per_tick}) {
      EXPECT_NEAR(LineInverseOffsetExact(p, m), RampOffsetByBruteForce(p, m), 1e-9)
          << "m = " << m << " v_max = " << p.v_max_deg_per_tick;
    }
  }
}

// For Table 1's parameters, the closed form is the exact answer shifted by the integral's half
// tick (m / 2) plus the midpoint-rule error at f's two kinks: a cell of the sum holding a kink errs
// by at most m v/(8 theta_0), two such cells move S by at most m v/(4 a theta_0), and S rises at
// least v/(a theta_0) per degree while one whole cell is linear, so C moves by at most m / 4. (The
// last step needs a whole linear cell at the root; with a = 1 and theta_0 near v_max it fails.)
TEST(LineInverse, ClosedAgreesWithBruteForceRampWithinTheIntegralApproximation) {
  for (double m = 0.0625; m < 2.5; m += 0.0625) {
    const double brute = RampOffsetByBruteForce(kPaper, m);
    const double closed = LineInverseOffsetClosed(kPaper, m);
    EXPECT_NEAR(closed - brute, m / 2.0, m / 4.0) << "m = " << m;
  }
}

TEST(LineInverse, ClosedFormIsContinuousWhereEquation10Switches) {
  // Eq. 10 switches at m* = theta_0 / (theta_0/v + a/2) = 7 / 5.8; there eq. 11 and eq. 12 meet.
  const double m_star = 7.0 / 5.8;
  EXPECT_NEAR(LineInverseOffsetClosed(kPaper, m_star - 1e-9),
              LineInverseOffsetClosed(kPaper, m_star + 1e-9), 1e-6);
  EXPECT_NEAR(LineInverseOffsetClosed(kPaper, m_star), m_star * 9.8, 1e-6);
}

TEST(LineInverse, TopSpeedUsesTheThreshold) {
  // theta_0 + (l + a) v_max = 7 + 10 * 2.5 = 32 deg.
  for (CmMethod method : {CmMethod::kClosed, CmMethod::kExact}) {
    EXPECT_DOUBLE_EQ(LineInverseOffset(kPaper, 2.5, method), 32.0);
    EXPECT_DOUBLE_EQ(LineInverseOffset(kPaper, -2.5, method), -32.0);
  }
  // The closed form tends to the threshold as m -> v_max (eq. 12's root vanishes).
  EXPECT_NEAR(LineInverseOffsetClosed(kPaper, 2.5 - 1e-10), 32.0, 1e-3);
}

TEST(LineInverse, OddInSlopeAndZeroForAFlatLine) {
  for (double m : {0.3, 1.7, 2.4}) {
    EXPECT_DOUBLE_EQ(LineInverseOffsetExact(kPaper, -m), -LineInverseOffsetExact(kPaper, m));
    EXPECT_DOUBLE_EQ(LineInverseOffsetClosed(kPaper, -m), -LineInverseOffsetClosed(kPaper, m));
  }
  EXPECT_DOUBLE_EQ(LineInverseOffsetExact(kPaper, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(LineInverseOffsetClosed(kPaper, 0.0), 0.0);
}

TEST(LineInverse, ExactSolvesEquation6) {
  for (double m = -2.4; m < 2.45; m += 0.2) {
    EXPECT_NEAR(LineResponse(kPaper, m, LineInverseOffsetExact(kPaper, m)), m, 1e-12);
  }
}

TEST(LineInverse, RejectsSlopesAboveVmax) {
  EXPECT_THROW(LineInverseOffsetExact(kPaper, 2.6), std::invalid_argument);
  EXPECT_THROW(LineInverseOffsetClosed(kPaper, -3.0), std::invalid_argument);
  EXPECT_THROW(LineInverseOffsetExact(kPaper, NAN), std::invalid_argument);
}

TEST(LineInverse, ClosedFormRefusesParametersOutsideEquation13) {
  EXPECT_THROW(LineInverseOffsetClosed({2.0, 1.5, 0, 3}, 0.5), std::domain_error);   // theta_0 < v
  EXPECT_THROW(LineInverseOffsetClosed({2.5, 7.0, 4, 12}, 0.5), std::domain_error);  // 28 < 30
  EXPECT_NO_THROW(LineInverseOffsetExact({2.5, 7.0, 4, 12}, 0.5));
}

}  // namespace
}  // namespace leglab
