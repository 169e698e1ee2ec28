#include "leglab/model/trajectories.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "test_legs.h"

namespace leglab {
namespace {

TEST(StepTest, Equation1) {
  const std::vector<double> r = StepTestRequests(40.0);
  ASSERT_EQ(r.size(), 88u);
  for (int t = 0; t < 44; ++t) EXPECT_EQ(r[t], 40.0) << t;
  for (int t = 44; t < 88; ++t) EXPECT_EQ(r[t], 0.0) << t;
  const std::vector<double> odd = StepTestRequests(110.0, 5);  // t < 2.5: t = 0, 1, 2
  EXPECT_EQ(odd, (std::vector<double>{110.0, 110.0, 110.0, 0.0, 0.0}));
  EXPECT_THROW(StepTestRequests(40.0, 1), std::invalid_argument);
}

TEST(HalfEllipse, ShapeByHand) {
  HalfEllipseLocus locus;
  locus.length_mm = 40.0;
  locus.height_mm = 30.0;
  locus.ground_fraction = 0.5;
  locus.centre_mm = {10.0, 70.0, -110.0};
  locus.t_step_ticks = 88;
  const auto path = HalfEllipseFootPath(locus);
  ASSERT_EQ(path.size(), 88u);
  // Touch-down at the front, lift-off at the back after 44 ticks, on the ground in between
  // at a constant 40/44 mm per tick backward.
  EXPECT_NEAR((path[0] - Eigen::Vector3d(30.0, 70.0, -110.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((path[44] - Eigen::Vector3d(-10.0, 70.0, -110.0)).norm(), 0.0, 1e-12);
  for (int t = 1; t <= 44; ++t) {
    EXPECT_NEAR(path[t].x() - path[t - 1].x(), -40.0 / 44.0, 1e-12);
    EXPECT_EQ(path[t - 1].z(), -110.0);
  }
  // Top of the arc half way through the flight: the centre, 30 mm up.
  EXPECT_NEAR((path[66] - Eigen::Vector3d(10.0, 70.0, -80.0)).norm(), 0.0, 1e-12);
  // Every flight point lies on the ellipse ((x - 10)/20)^2 + ((z + 110)/30)^2 = 1.
  for (int t = 44; t < 88; ++t) {
    const double ex = (path[t].x() - 10.0) / 20.0, ez = (path[t].z() + 110.0) / 30.0;
    EXPECT_NEAR(ex * ex + ez * ez, 1.0, 1e-12) << t;
  }
}

TEST(HalfEllipse, SkewShearsTheLocusInTheGroundPlane) {
  HalfEllipseLocus plain;
  plain.length_mm = 40.0;
  plain.height_mm = 30.0;
  plain.centre_mm = {10.0, 70.0, -110.0};
  HalfEllipseLocus skewed = plain;
  skewed.skew = 0.5;
  const auto a = HalfEllipseFootPath(plain);
  const auto b = HalfEllipseFootPath(skewed);
  ASSERT_EQ(b.size(), 88u);
  // By hand: the front end (x offset +20) moves 0.5 * 20 = 10 mm to +y, the back end 10 mm
  // to -y, the top of the arc (x offset 0) not at all; x and z are the plain locus's.
  EXPECT_NEAR((b[0] - Eigen::Vector3d(30.0, 80.0, -110.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((b[44] - Eigen::Vector3d(-10.0, 60.0, -110.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((b[66] - Eigen::Vector3d(10.0, 70.0, -80.0)).norm(), 0.0, 1e-12);
  for (size_t t = 0; t < b.size(); ++t) {
    EXPECT_EQ(b[t].x(), a[t].x()) << t;
    EXPECT_EQ(b[t].z(), a[t].z()) << t;
    EXPECT_NEAR(b[t].y() - 70.0, 0.5 * (a[t].x() - 10.0), 1e-12) << t;
  }
  skewed.skew = std::nan("");
  EXPECT_THROW(HalfEllipseFootPath(skewed), std::invalid_argument);
}

// swing_end_speed_fraction 1 (against the foot's slip on the single-leg stand): the foot leaves and
// meets the ground at the stance's speed. Checked by finite differences on a finely sampled step
// (8800 ticks, h = 1 / 4400 of the flight), against the speed the flat bottom runs at (L per unit
// of the flight's s here): a one-sided difference misses the end speed by at most max|x''| h / 2 =
// (pi^2 L / 2 + 6 L) / 8800 = 1.24e-3 L.
TEST(HalfEllipse, MatchedSwingLeavesAndMeetsTheGroundAtTheStanceSpeed) {
  HalfEllipseLocus locus;
  locus.length_mm = 40.0;
  locus.height_mm = 30.0;
  locus.centre_mm = {10.0, 70.0, -110.0};
  locus.t_step_ticks = 8800;
  locus.swing_end_speed_fraction = 1.0;
  const auto path = HalfEllipseFootPath(locus);
  const int ground = 4400, period = 8800;
  const double stance_speed = -40.0 / ground;  // mm per tick, backward
  // The stance is untouched: its speed, here from the flat bottom's own ticks.
  EXPECT_NEAR(path[1].x() - path[0].x(), stance_speed, 1e-12);
  EXPECT_NEAR(path[ground].x() - path[ground - 1].x(), stance_speed, 1e-12);
  // Lift-off: the first flight ticks keep the stance's speed; touch-down: the last flight
  // tick to the wrap-around (path[0]) too.
  const double bound = (std::numbers::pi * std::numbers::pi / 2.0 + 6.0) / 8800.0;
  EXPECT_NEAR((path[ground + 1].x() - path[ground].x()) / stance_speed, 1.0, bound);
  EXPECT_NEAR((path[0].x() - path[period - 1].x()) / stance_speed, 1.0, bound);
  // Position continuous (no tick moves the foot farther than the fastest flight speed, pi L /
  // 2 + L / 2 per unit of s at s = 1/2, allows) and the speed continuous: consecutive
  // differences change by at most max|x''| h^2 = 10.9 L / 4400^2 per tick, 2.3e-5 mm.
  const double max_step = (std::numbers::pi / 2.0 + 0.5) * 40.0 / 4400.0;
  double max_change = 0.0;
  for (int t = 0; t < period; ++t) {
    const auto& a = path[(t + period - 1) % period];
    const auto& b = path[t];
    const auto& c = path[(t + 1) % period];
    EXPECT_LE(std::abs(b.x() - a.x()), max_step * 1.001) << t;
    max_change = std::max(max_change, std::abs((c.x() - b.x()) - (b.x() - a.x())));
  }
  EXPECT_LT(max_change, (std::numbers::pi * std::numbers::pi / 2.0 + 6.0) * 40.0 / 4400.0 / 4400.0);
  // The price: the flight overshoots the flat bottom at both ends, by 0.04756 L (the cubic's
  // extremum, found by a brute-force scan of s in steps of 1e-5 off line: 0.547562 L from
  // the centre at s = 0.0973 and 0.9027, where z is 0.301 of the height).
  double front = 0.0, back = 0.0;
  for (const auto& p : path) {
    front = std::max(front, p.x() - 10.0);
    back = std::min(back, p.x() - 10.0);
  }
  EXPECT_NEAR(front, 0.547562 * 40.0, 1e-3);
  EXPECT_NEAR(back, -0.547562 * 40.0, 1e-3);
  // The plain half-ellipse, by contrast, leaves at rest: its first flight tick moves the foot
  // forward by L/2 (1 - cos(pi / 4400)), 1e-5 of the stance's tick.
  HalfEllipseLocus plain = locus;
  plain.swing_end_speed_fraction = 0.0;
  const auto still = HalfEllipseFootPath(plain);
  EXPECT_NEAR(still[ground + 1].x() - still[ground].x(),
              20.0 * (1.0 - std::cos(std::numbers::pi / 4400.0)), 1e-12);
  // z is the half-ellipse's at every tick; y too.
  for (int t = 0; t < period; ++t) {
    EXPECT_EQ(path[t].z(), still[t].z()) << t;
    EXPECT_EQ(path[t].y(), still[t].y()) << t;
  }
}

// The same swing worked by hand at a tick of the 88-tick step: half way through the flight (s
// = 1/2) the cubic s - 3 s^2 + 2 s^3 is 0, so the top of the arc is the half-ellipse's; a
// quarter of the way (s = 1/4, tick 55), it is 1/4 - 3/16 + 2/64 = 3/32, so the foot is
// f L (44 / 44) 3 / 32 = 0.5 x 40 x 3 / 32 = 1.875 mm behind the half-ellipse's point.
// 0 gives the half-ellipse bit for bit; negative or NaN fractions are refused.
TEST(HalfEllipse, MatchedSwingByHand) {
  HalfEllipseLocus plain;
  plain.length_mm = 40.0;
  plain.height_mm = 30.0;
  plain.centre_mm = {10.0, 70.0, -110.0};
  HalfEllipseLocus half = plain;
  half.swing_end_speed_fraction = 0.5;
  const auto a = HalfEllipseFootPath(plain);
  const auto b = HalfEllipseFootPath(half);
  for (int t = 0; t < 44; ++t) EXPECT_EQ(a[t], b[t]) << t;
  EXPECT_NEAR((b[66] - Eigen::Vector3d(10.0, 70.0, -80.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(b[55].x() - a[55].x(), -1.875, 1e-12);
  EXPECT_NEAR(b[77].x() - a[77].x(), +1.875, 1e-12);  // s = 3/4: -3/32
  HalfEllipseLocus zero = plain;
  zero.swing_end_speed_fraction = 0.0;
  EXPECT_EQ(HalfEllipseFootPath(zero), a);
  zero.swing_end_speed_fraction = -0.1;
  EXPECT_THROW(HalfEllipseFootPath(zero), std::invalid_argument);
  zero.swing_end_speed_fraction = std::nan("");
  EXPECT_THROW(HalfEllipseFootPath(zero), std::invalid_argument);
}

// The slow lift-off (against the foot's slip at lift-off on the single-leg stand) worked by hand on
// the 88-tick step (44 flight ticks, L 40, H 30): a 4 mm ramp over 4 ticks, a = 4 / 44. Flight tick
// k (k = 0 at lift-off) lies on the line at k mm while the squeezed arc 30 sin(pi (k - 4) / 40) is
// lower: k = 5: 2.354 < 5, k = 6: 4.693 < 6; from k = 7 (7.003 > 7) the arc. Its top is at k = 24
// (30 mm), the last flight tick (k = 43) at 30 sin(39 pi / 40) = 2.354 mm; x, y and the stance are
// the half-ellipse's, and 0 mm is the half-ellipse bit for bit.
TEST(HalfEllipse, SlowLiftOffByHand) {
  HalfEllipseLocus plain;
  plain.length_mm = 40.0;
  plain.height_mm = 30.0;
  plain.centre_mm = {10.0, 70.0, -110.0};
  HalfEllipseLocus ramp = plain;
  ramp.liftoff_ramp_mm = 4.0;
  ramp.liftoff_ramp_ticks = 4;
  const auto a = HalfEllipseFootPath(plain);
  const auto b = HalfEllipseFootPath(ramp);
  for (int t = 0; t <= 44; ++t) EXPECT_EQ(a[t], b[t]) << t;
  for (int t = 0; t < 88; ++t) {
    EXPECT_EQ(a[t].x(), b[t].x()) << t;
    EXPECT_EQ(a[t].y(), b[t].y()) << t;
  }
  for (int k = 0; k <= 6; ++k) EXPECT_NEAR(b[44 + k].z() + 110.0, k, 1e-12) << k;
  for (int k = 7; k < 44; ++k) {
    EXPECT_NEAR(b[44 + k].z() + 110.0, 30.0 * std::sin(std::numbers::pi * (k - 4) / 40.0), 1e-12)
        << k;
  }
  EXPECT_NEAR(b[44 + 24].z() + 110.0, 30.0, 1e-12);
  EXPECT_NEAR(b[87].z() + 110.0, 2.354, 1e-3);
  // Continuous: no flight tick rises or falls by more than the squeezed arc's top speed, 30 pi
  // / 40 = 2.356 mm per tick (the line's 1 mm per tick is below it).
  for (int t = 45; t < 88; ++t) {
    EXPECT_LE(std::abs(b[t].z() - b[t - 1].z()), 30.0 * std::numbers::pi / 40.0 + 1e-12) << t;
  }
  HalfEllipseLocus zero = plain;
  zero.liftoff_ramp_ticks = 4;  // no height: no ramp
  EXPECT_EQ(HalfEllipseFootPath(zero), a);
  // Refused: a ramp without ticks, one as long as the flight, a negative or NaN height, and a
  // line that would overtop the arc: 8 mm over 4 ticks reaches 8 (1 + a) / (2 a) = 48 mm > 30
  // at the arc's top, while 4.5 mm (27 mm) stays under it.
  HalfEllipseLocus bad = ramp;
  bad.liftoff_ramp_ticks = 0;
  EXPECT_THROW(HalfEllipseFootPath(bad), std::invalid_argument);
  bad.liftoff_ramp_ticks = 44;
  EXPECT_THROW(HalfEllipseFootPath(bad), std::invalid_argument);
  bad = ramp;
  bad.liftoff_ramp_mm = -1.0;
  EXPECT_THROW(HalfEllipseFootPath(bad), std::invalid_argument);
  bad.liftoff_ramp_mm = std::nan("");
  EXPECT_THROW(HalfEllipseFootPath(bad), std::invalid_argument);
  bad.liftoff_ramp_mm = 8.0;
  EXPECT_THROW(HalfEllipseFootPath(bad), std::invalid_argument);
  bad.liftoff_ramp_mm = 4.5;
  EXPECT_NO_THROW(HalfEllipseFootPath(bad));
}

TEST(PitchFootPath, TurnsLevelPointsIntoThePitchedBody) {
  const Eigen::Vector3d pivot(59.5, 59.2, 0.0);
  const std::vector<Eigen::Vector3d> level = {pivot + Eigen::Vector3d(0.0, 0.0, -100.0),
                                              pivot + Eigen::Vector3d(100.0, 5.0, 0.0)};
  // Nose down 30 deg, by hand (sin 30 = 1/2, cos 30 = sqrt(3)/2): straight below the
  // shoulder in the level frame is ahead of it and less deep in the body frame; level ground
  // ahead rises toward the body's top; y is untouched.
  const auto body = PitchFootPath(level, pivot, 30.0);
  const double c = std::sqrt(3.0) / 2.0;
  EXPECT_NEAR((body[0] - (pivot + Eigen::Vector3d(50.0, 0.0, -100.0 * c))).norm(), 0.0, 1e-12);
  EXPECT_NEAR((body[1] - (pivot + Eigen::Vector3d(100.0 * c, 5.0, 50.0))).norm(), 0.0, 1e-12);
  // The cited walk: front shoulder 77 mm and rear shoulder 112 mm above level ground, 119 mm
  // apart. The rear shoulder, 119 mm behind the front one in the body,
  // is then 35 mm above it in the level frame (pitch asin(35 / 119), 17.1 deg); turning that
  // level point gives it back.
  const double pitch_deg = std::asin(35.0 / 119.0) * 180.0 / std::numbers::pi;
  const double run = std::sqrt(119.0 * 119.0 - 35.0 * 35.0);
  const auto rear = PitchFootPath({pivot + Eigen::Vector3d(-run, 0.0, 35.0)}, pivot, pitch_deg);
  EXPECT_NEAR((rear[0] - (pivot + Eigen::Vector3d(-119.0, 0.0, 0.0))).norm(), 0.0, 1e-12);
  // No pitch: the same bits.
  const auto same = PitchFootPath(level, pivot, 0.0);
  EXPECT_EQ(same, level);
  EXPECT_THROW(PitchFootPath(level, pivot, 91.0), std::invalid_argument);
  EXPECT_THROW(PitchFootPath(level, pivot, std::nan("")), std::invalid_argument);
}

TEST(HalfEllipse, RejectsBadParameters) {
  HalfEllipseLocus locus;
  locus.ground_fraction = 1.0;
  EXPECT_THROW(HalfEllipseFootPath(locus), std::invalid_argument);
  locus = {};
  locus.height_mm = -1.0;
  EXPECT_THROW(HalfEllipseFootPath(locus), std::invalid_argument);
}

TEST(JointTrajectory, InverseKinematicsOfEveryTick) {
  const LegGeometry g = testing::FrontLeftLeg();
  HalfEllipseLocus locus;
  locus.centre_mm = {70.0, 75.0, -115.0};
  const auto path = HalfEllipseFootPath(locus);
  const auto angles = JointTrajectoryDeg(g, path);
  ASSERT_EQ(angles.size(), path.size());
  for (size_t t = 0; t < path.size(); ++t) {
    const Eigen::Vector3d foot = ForwardKinematics(g, angles[t] * (std::numbers::pi / 180.0));
    EXPECT_LT((foot - path[t]).norm(), 1e-9) << t;
  }
}

TEST(JointTrajectory, UnreachableTickIsNamed) {
  const LegGeometry g = testing::FrontLeftLeg();
  std::vector<Eigen::Vector3d> path = {{60.0, 60.0, -120.0}, {60.0, 60.0, -300.0}};
  try {
    JointTrajectoryDeg(g, path);
    FAIL();
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("tick 1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace leglab
