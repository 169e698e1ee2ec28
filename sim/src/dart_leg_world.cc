// The leg on DART: one skeleton in joint coordinates, built from the LegDescription (the same
// bodies, lumped as for ODE) rather than by DART's URDF loader, so that both engines move the
// same masses. Design and measurements: docs/design/dart.md.

#include <dart/dynamics/BodyNode.hpp>
#include <dart/dynamics/RevoluteJoint.hpp>
#include <dart/dynamics/Skeleton.hpp>
#include <dart/simulation/World.hpp>

#include <Eigen/Geometry>
#include <cassert>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/sim/leg_world.h"
#include "link_poses.h"
#include "physics_world.h"

namespace leglab::sim {
namespace {

class DartLegWorld final : public PhysicsWorld {
 public:
  explicit DartLegWorld(const LegDescription& leg);

  LegAngles AnglesRad() const override;
  LegAngles RatesRadPerS() const override;
  void SetMotor(int joint, double speed_rad_per_s, double max_torque_nm) override;
  void Step(double dt_s) override;
  void SetConfigurationRad(const LegAngles& q_rad) override;
  const PlantTelemetry& stand_state() const override { return kNoStand; }
  bool has_stand() const override { return false; }
  std::array<double, 3> LinkOriginMm(int link) const override;
  double MechanicalEnergyJ() const override;
  double KineticEnergyJ() const override;
  std::string StateProblem() const override;

 private:
  static inline const PlantTelemetry kNoStand{};

  const LegDescription& leg_;
  dart::simulation::WorldPtr world_;
  dart::dynamics::SkeletonPtr skeleton_;
  std::vector<dart::dynamics::BodyNode*> bodies_;  // LegDescription::bodies' order
  std::array<dart::dynamics::RevoluteJoint*, kLegJoints> joints_{};  // LegJoint order
};

DartLegWorld::DartLegWorld(const LegDescription& leg)
    : leg_(leg),
      world_(dart::simulation::World::create("leglab")),
      skeleton_(dart::dynamics::Skeleton::create("leg")),
      bodies_(leg.bodies.size(), nullptr) {
  // Each moving link's body node carries the link's frame; its joint is the URDF joint: the
  // link's origin in the frame of the body its parent rides on (the root frame, which is the
  // world, for a parent fixed to the root), then the turn about the link's own axis.
  for (size_t i = 1; i < leg.links.size(); ++i) {
    const LinkDescription& link = leg.links[i];
    if (link.joint < 0) continue;
    const LinkDescription& parent = leg.links[link.parent];
    dart::dynamics::BodyNode* parent_node = parent.body >= 0 ? bodies_[parent.body] : nullptr;
    const JointDescription& description = leg.joints[link.joint];
    dart::dynamics::RevoluteJoint::Properties joint;
    joint.mName = description.name;
    joint.mAxis = ToEigen(link.axis);
    joint.mT_ParentBodyToJoint = ToEigen(parent.in_body) * ToEigen(link.origin);
    joint.mT_ChildBodyToJoint = Eigen::Isometry3d::Identity();
    joint.mPositionLowerLimits[0] = description.lower_rad - LegWorld::kStopMarginRad;
    joint.mPositionUpperLimits[0] = description.upper_rad + LegWorld::kStopMarginRad;
    joint.mIsPositionLimitEnforced = true;
    dart::dynamics::BodyNode::Properties body;
    body.mName = link.name;
    const BodyDescription& mass = leg.bodies[link.body];
    body.mInertia =
        dart::dynamics::Inertia(mass.mass_kg, ToEigen(mass.com_m), ToEigen(mass.inertia_kg_m2));
    auto [created_joint, created_body] =
        skeleton_->createJointAndBodyNodePair<dart::dynamics::RevoluteJoint>(parent_node, joint,
                                                                             body);
    created_joint->setActuatorType(dart::dynamics::Joint::SERVO);
    created_joint->setForceLowerLimit(0, 0.0);
    created_joint->setForceUpperLimit(0, 0.0);
    joints_[link.joint] = created_joint;
    bodies_[link.body] = created_body;
  }
  world_->setGravity(Eigen::Vector3d(0.0, 0.0, -LegWorld::kGravityMPerS2));
  world_->addSkeleton(skeleton_);
}

LegAngles DartLegWorld::AnglesRad() const {
  LegAngles angles{};
  for (int j = 0; j < kLegJoints; ++j) angles[j] = joints_[j]->getPosition(0);
  return angles;
}

LegAngles DartLegWorld::RatesRadPerS() const {
  LegAngles rates{};
  for (int j = 0; j < kLegJoints; ++j) rates[j] = joints_[j]->getVelocity(0);
  return rates;
}

void DartLegWorld::SetMotor(int joint, double speed_rad_per_s, double max_torque_nm) {
  assert(joint >= 0 && joint < kLegJoints && max_torque_nm >= 0.0);
  // A servo joint: the constraint solver holds the speed with at most the torque limit, as
  // ODE's hinge motor does.
  joints_[joint]->setCommand(0, speed_rad_per_s);
  joints_[joint]->setForceLowerLimit(0, -max_torque_nm);
  joints_[joint]->setForceUpperLimit(0, max_torque_nm);
}

void DartLegWorld::Step(double dt_s) {
  if (world_->getTimeStep() != dt_s) world_->setTimeStep(dt_s);
  world_->step(/*resetCommand=*/false);  // the motors hold their speeds until set again
}

void DartLegWorld::SetConfigurationRad(const LegAngles& q_rad) {
  for (int j = 0; j < kLegJoints; ++j) {
    joints_[j]->setPosition(0, q_rad[j]);
    joints_[j]->setVelocity(0, 0.0);
  }
}

std::array<double, 3> DartLegWorld::LinkOriginMm(int index) const {
  const LinkDescription& link = leg_.links[index];
  const Eigen::Isometry3d body_link_pose =
      link.body >= 0 ? bodies_[link.body]->getWorldTransform() : Eigen::Isometry3d::Identity();
  const Eigen::Vector3d origin_mm = 1000.0 * (body_link_pose * ToEigen(link.in_body)).translation();
  return {origin_mm.x(), origin_mm.y(), origin_mm.z()};
}

double DartLegWorld::KineticEnergyJ() const { return skeleton_->computeKineticEnergy(); }

double DartLegWorld::MechanicalEnergyJ() const {
  // Summed here from each body's centre of mass: DART 6.12's BodyNode::computePotentialEnergy
  // uses the body frame's origin instead.
  double potential = 0.0;
  for (const dart::dynamics::BodyNode* body : bodies_) {
    potential += body->getMass() * LegWorld::kGravityMPerS2 * body->getCOM().z();
  }
  return skeleton_->computeKineticEnergy() + potential;
}

std::string DartLegWorld::StateProblem() const {
  for (int j = 0; j < kLegJoints; ++j) {
    const double angle = joints_[j]->getPosition(0);
    const double rate = joints_[j]->getVelocity(0);
    if (!std::isfinite(angle) || !(std::abs(rate) <= LegWorld::kExplodedRateRadPerS)) {
      return "joint '" + leg_.joints[j].name + "' is at " + std::to_string(angle) +
             " rad turning at " + std::to_string(rate) + " rad/s (limit " +
             std::to_string(LegWorld::kExplodedRateRadPerS) + ")";
    }
  }
  return {};
}

}  // namespace

std::unique_ptr<PhysicsWorld> MakeDartWorld(const LegDescription& leg, const StandConfig& stand) {
  if (stand.enabled) {
    throw std::invalid_argument(std::string(kDartHasNoStand));
  }
  return std::make_unique<DartLegWorld>(leg);
}

bool BuiltWithDart() { return true; }

}  // namespace leglab::sim
