#include <ode/ode.h>

#include <Eigen/Geometry>
#include <cassert>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "leglab/sim/leg_world.h"
#include "link_poses.h"
#include "ode_stand.h"
#include "ode_world.h"
#include "physics_world.h"

namespace leglab::sim {
namespace {

// An ODE vector (dVector3 or a body's position, velocity) as Eigen.
Eigen::Vector3d FromOde(const dReal* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

Eigen::Matrix3d RotationOf(dBodyID body) {
  const dReal* r = dBodyGetRotation(body);  // 3x4 row-major
  Eigen::Matrix3d rotation;
  rotation << r[0], r[1], r[2], r[4], r[5], r[6], r[8], r[9], r[10];
  return rotation;
}

void SetRotation(dBodyID body, const Eigen::Matrix3d& rotation) {
  dMatrix3 r;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      r[i * 4 + j] = rotation(i, j);
    }
    r[i * 4 + 3] = 0.0;
  }
  dBodySetRotation(body, r);
}

class OdeLegWorld final : public PhysicsWorld {
 public:
  OdeLegWorld(const LegDescription& leg, const StandConfig& stand);

  LegAngles AnglesRad() const override;
  LegAngles RatesRadPerS() const override;
  void SetMotor(int joint, double speed_rad_per_s, double max_torque_nm) override;
  void Step(double dt_s) override;
  void SetConfigurationRad(const LegAngles& q_rad) override;
  const PlantTelemetry& stand_state() const override;
  bool has_stand() const override { return stand_ != nullptr; }
  std::array<double, 3> LinkOriginMm(int link) const override;
  double MechanicalEnergyJ() const override;
  double KineticEnergyJ() const override;
  std::string StateProblem() const override;

 private:
  // One ODE body: the description's body, with its mass in Eigen form for the energy sums.
  struct Body {
    dBodyID id = nullptr;
    int link = -1;                                          // the link whose frame it carries
    Eigen::Vector3d com_in_link = Eigen::Vector3d::Zero();  // body origin in that frame, m
    double mass_kg = 0.0;
    Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  // about com, link axes
  };

  const LegDescription& leg_;
  std::optional<OdeWorld> world_;  // created once ODE is ready
  std::vector<Body> bodies_;
  std::array<dJointID, kLegJoints> hinges_{};
  // The stand, when there is one; destroyed before the world (declared after it).
  std::unique_ptr<Stand> stand_;

  // The body a root-attached hinge hangs on: the world in the air, the carriage on the stand.
  dBodyID RootBody() const { return stand_ ? stand_->carriage : nullptr; }

  // Pose of a body's link frame in the world, from ODE's state.
  Eigen::Isometry3d BodyLinkPose(const Body& body) const {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = RotationOf(body.id);
    pose.translation() = FromOde(dBodyGetPosition(body.id)) - pose.linear() * body.com_in_link;
    return pose;
  }

  void BuildBodies();
  void BuildHinges();
  void BuildStand(const StandConfig& config);
};

void OdeLegWorld::BuildBodies() {
  const std::vector<Eigen::Isometry3d> poses = LinkPoses(leg_.links, LegAngles{});
  for (const BodyDescription& description : leg_.bodies) {
    Body body{.link = description.link,
              .com_in_link = ToEigen(description.com_m),
              .mass_kg = description.mass_kg,
              .inertia_kg_m2 = ToEigen(description.inertia_kg_m2)};
    dMass mass;
    const Eigen::Matrix3d& in = body.inertia_kg_m2;
    dMassSetParameters(&mass, body.mass_kg, 0.0, 0.0, 0.0, in(0, 0), in(1, 1), in(2, 2), in(0, 1),
                       in(0, 2), in(1, 2));
    if (dMassCheck(&mass) == 0) {
      throw std::invalid_argument("link '" + leg_.links[body.link].name +
                                  "': ODE rejects its combined mass");
    }
    body.id = dBodyCreate(world_->get());
    dBodySetMass(body.id, &mass);
    const Eigen::Isometry3d& pose = poses[body.link];
    const Eigen::Vector3d com_world = pose * body.com_in_link;
    dBodySetPosition(body.id, com_world.x(), com_world.y(), com_world.z());
    SetRotation(body.id, pose.linear());
    bodies_.push_back(body);
  }
}

void OdeLegWorld::BuildHinges() {
  // Built at q = 0, which ODE takes as each hinge's zero angle. Attaching (child, parent) makes
  // ODE's angle the child's turn about the axis relative to the parent: the URDF's sign.
  for (std::size_t i = 1; i < leg_.links.size(); ++i) {
    const LinkDescription& link = leg_.links[i];
    if (link.joint < 0) {
      continue;
    }
    const JointDescription& joint = leg_.joints[link.joint];
    const int parent_body = leg_.links[link.parent].body;
    const dJointID hinge = dJointCreateHinge(world_->get(), nullptr);
    dJointAttach(hinge, bodies_[link.body].id,
                 parent_body >= 0 ? bodies_[parent_body].id : RootBody());
    dJointSetHingeAnchor(hinge, joint.position_m[0], joint.position_m[1], joint.position_m[2]);
    dJointSetHingeAxis(hinge, joint.axis[0], joint.axis[1], joint.axis[2]);
    dJointSetHingeParam(hinge, dParamLoStop, joint.lower_rad - LegWorld::kStopMarginRad);
    dJointSetHingeParam(hinge, dParamHiStop, joint.upper_rad + LegWorld::kStopMarginRad);
    dJointSetHingeParam(hinge, dParamBounce, 0.0);
    dJointSetHingeParam(hinge, dParamFMax, 0.0);
    hinges_[link.joint] = hinge;
  }
}

void OdeLegWorld::BuildStand(const StandConfig& config) {
  const int foot_link = leg_.FindLink(kFootLinkName);
  assert(foot_link > 0 && leg_.links[foot_link].body >= 0 && "the description has a moving foot");
  const Body& foot_body = bodies_[leg_.links[foot_link].body];
  // The foot's centre relative to the body's centre of mass, in the body's (link) axes.
  const Eigen::Vector3d foot_offset_m =
      ToEigen(leg_.links[foot_link].in_body.translation_m) - foot_body.com_in_link;
  stand_ = std::make_unique<Stand>(world_->get(), config, leg_.joints[kRotator].position_m[2],
                                   foot_body.id, foot_offset_m);
}

OdeLegWorld::OdeLegWorld(const LegDescription& leg, const StandConfig& stand) : leg_(leg) {
  EnsureOdeReady();
  world_.emplace();
  dWorldSetGravity(world_->get(), 0.0, 0.0, -LegWorld::kGravityMPerS2);
  BuildBodies();
  if (stand.enabled) BuildStand(stand);
  BuildHinges();
}

LegAngles OdeLegWorld::AnglesRad() const {
  LegAngles angles{};
  for (int j = 0; j < kLegJoints; ++j) {
    angles[j] = dJointGetHingeAngle(hinges_[j]);
  }
  return angles;
}

LegAngles OdeLegWorld::RatesRadPerS() const {
  LegAngles rates{};
  for (int j = 0; j < kLegJoints; ++j) {
    rates[j] = dJointGetHingeAngleRate(hinges_[j]);
  }
  return rates;
}

void OdeLegWorld::SetMotor(int joint, double speed_rad_per_s, double max_torque_nm) {
  assert(joint >= 0 && joint < kLegJoints && max_torque_nm >= 0.0);
  dJointSetHingeParam(hinges_[joint], dParamVel, speed_rad_per_s);
  dJointSetHingeParam(hinges_[joint], dParamFMax, max_torque_nm);
}

void OdeLegWorld::Step(double dt_s) {
  // A world built on one thread may be stepped on another (a moved plant): ODE needs its
  // per-thread data there too. After the first call on a thread this is one flag test.
  EnsureOdeReady();
  try {
    if (stand_) {
      stand_->Step(world_->get(), dt_s);
    } else {
      dWorldStep(world_->get(), dt_s);
    }
  } catch (...) {  // an ODE error (EnsureOdeReady) left the step half done
    world_->MarkBroken();
    throw;
  }
}

const PlantTelemetry& OdeLegWorld::stand_state() const {
  static const PlantTelemetry kNone{};
  return stand_ ? stand_->state : kNone;
}

void OdeLegWorld::SetConfigurationRad(const LegAngles& q_rad) {
  const std::vector<Eigen::Isometry3d> poses = LinkPoses(leg_.links, q_rad);
  // On the stand: the carriage on its stop, or as high as keeps the foot out of the floor.
  Eigen::Vector3d lift = Eigen::Vector3d::Zero();
  if (stand_) {
    const int foot = leg_.FindLink(kFootLinkName);
    lift.z() = stand_->PlaceCarriage(poses[foot].translation().z());
  }
  for (const Body& body : bodies_) {
    const Eigen::Isometry3d& pose = poses[body.link];
    const Eigen::Vector3d com_world = pose * body.com_in_link + lift;
    dBodySetPosition(body.id, com_world.x(), com_world.y(), com_world.z());
    SetRotation(body.id, pose.linear());
    dBodySetLinearVel(body.id, 0.0, 0.0, 0.0);
    dBodySetAngularVel(body.id, 0.0, 0.0, 0.0);
  }
}

std::array<double, 3> OdeLegWorld::LinkOriginMm(int index) const {
  const LinkDescription& link = leg_.links[index];
  const Eigen::Isometry3d body_link_pose =
      link.body >= 0 ? BodyLinkPose(bodies_[link.body]) : Eigen::Isometry3d::Identity();
  Eigen::Vector3d origin_mm = 1000.0 * (body_link_pose * ToEigen(link.in_body)).translation();
  // On the stand the body frame is the carriage's: the world frame raised by its height (and
  // moved along x and y with the sled, when there is one).
  if (stand_) {
    origin_mm.z() -= 1000.0 * stand_->CarriageZM();
    if (stand_->has_sled()) {
      origin_mm.x() -= 1000.0 * stand_->SledXM();
      origin_mm.y() -= 1000.0 * stand_->SledYM();
    }
    if (link.body < 0) origin_mm = 1000.0 * ToEigen(link.in_body.translation_m);
  }
  return {origin_mm.x(), origin_mm.y(), origin_mm.z()};
}

double OdeLegWorld::KineticEnergyJ() const {
  double energy = 0.0;
  for (const Body& body : bodies_) {
    const Eigen::Vector3d velocity = FromOde(dBodyGetLinearVel(body.id));
    // The inertia is in link axes, which are the body's axes.
    const Eigen::Vector3d omega =
        RotationOf(body.id).transpose() * FromOde(dBodyGetAngularVel(body.id));
    energy +=
        0.5 * body.mass_kg * velocity.squaredNorm() + 0.5 * omega.dot(body.inertia_kg_m2 * omega);
  }
  if (stand_) energy += stand_->CarriageKineticEnergyJ();
  return energy;
}

double OdeLegWorld::MechanicalEnergyJ() const {
  double potential = 0.0;
  for (const Body& body : bodies_) {
    potential += body.mass_kg * LegWorld::kGravityMPerS2 * dBodyGetPosition(body.id)[2];
  }
  if (stand_) {
    potential += stand_->CarriagePotentialEnergyJ(LegWorld::kGravityMPerS2);
    potential += stand_->SledSpringEnergyJ();
  }
  return KineticEnergyJ() + potential;
}

std::string OdeLegWorld::StateProblem() const {
  if (stand_) {
    std::string problem = stand_->StateProblem();
    if (!problem.empty()) return problem;
  }
  for (const Body& body : bodies_) {
    const dReal* values[] = {dBodyGetPosition(body.id), dBodyGetQuaternion(body.id),
                             dBodyGetLinearVel(body.id), dBodyGetAngularVel(body.id)};
    for (const dReal* v : values) {
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
        return "link '" + leg_.links[body.link].name + "' has a non-finite pose or velocity";
      }
    }
  }
  for (int j = 0; j < kLegJoints; ++j) {
    const dJointID hinge = hinges_[j];
    const double rate = dJointGetHingeAngleRate(hinge);
    if (!std::isfinite(dJointGetHingeAngle(hinge)) ||
        !(std::abs(rate) <= LegWorld::kExplodedRateRadPerS)) {
      return "joint '" + leg_.joints[j].name + "' turns at " + std::to_string(rate) +
             " rad/s (limit " + std::to_string(LegWorld::kExplodedRateRadPerS) + ")";
    }
    dVector3 anchor1;
    dVector3 anchor2;
    dJointGetHingeAnchor(hinge, anchor1);
    dJointGetHingeAnchor2(hinge, anchor2);
    const double gap_m = (FromOde(anchor1) - FromOde(anchor2)).norm();
    if (!(gap_m <= 1e-3)) {
      return "joint '" + leg_.joints[j].name + "' came apart: its anchors are " +
             std::to_string(gap_m * 1000.0) + " mm apart";
    }
  }
  return {};
}

}  // namespace

std::unique_ptr<PhysicsWorld> MakeOdeWorld(const LegDescription& leg, const StandConfig& stand) {
  return std::make_unique<OdeLegWorld>(leg, stand);
}

}  // namespace leglab::sim
