#include "leglab/sim/leg_world.h"

#include <ode/ode.h>

#include <Eigen/Geometry>
#include <cassert>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "link_poses.h"
#include "ode_stand.h"
#include "ode_world.h"

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

// A description built by hand rather than by LoadLegDescription must still index a tree: each
// parent before its child, each LegJoint moving one link, each body carried by its own link.
void CheckStructure(const LegDescription& leg) {
  const auto bad = [&leg](const std::string& what) {
    throw std::invalid_argument("leg description of '" + leg.urdf_path + "': " + what);
  };
  const int link_count = static_cast<int>(leg.links.size());
  const int body_count = static_cast<int>(leg.bodies.size());
  if (link_count == 0 || leg.links[0].parent != -1 || leg.links[0].body != -1) {
    bad("links[0] must be the root (no parent, no body)");
  }
  std::array<int, kLegJoints> moved{};
  for (int i = 1; i < link_count; ++i) {
    const LinkDescription& link = leg.links[i];
    if (link.parent < 0 || link.parent >= i || link.joint < -1 || link.joint >= kLegJoints ||
        link.body < -1 || link.body >= body_count) {
      bad("link '" + link.name + "' has a parent, joint or body index out of range");
    }
    if (link.joint >= 0) {
      ++moved[link.joint];
      if (link.body < 0 || leg.bodies[link.body].link != i) {
        bad("link '" + link.name + "' is moved by a joint but does not carry its own body");
      }
    } else if (link.body != leg.links[link.parent].body) {
      bad("link '" + link.name + "' is fixed to its parent but rides on another body");
    }
  }
  for (int j = 0; j < kLegJoints; ++j) {
    if (moved[j] != 1) {
      bad("joint '" + std::string(kLegJointNames[j]) + "' must move exactly one link, moves " +
          std::to_string(moved[j]));
    }
  }
  for (const BodyDescription& body : leg.bodies) {
    if (body.link < 1 || body.link >= link_count || leg.links[body.link].joint < 0) {
      bad("a body is carried by a link index that is out of range or not moved by a joint");
    }
  }
}

}  // namespace

struct LegWorld::Impl {
  // One ODE body: the description's body, with its mass in Eigen form for the energy sums.
  struct Body {
    dBodyID id = nullptr;
    int link = -1;                                          // the link whose frame it carries
    Eigen::Vector3d com_in_link = Eigen::Vector3d::Zero();  // body origin in that frame, m
    double mass_kg = 0.0;
    Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  // about com, link axes
  };

  LegDescription leg;
  std::optional<OdeWorld> world;  // created once ODE is ready
  std::vector<Body> bodies;
  std::array<dJointID, kLegJoints> hinges{};
  // The stand, when there is one; destroyed before the world (declared after it).
  std::unique_ptr<Stand> stand;

  // The body a root-attached hinge hangs on: the world in the air, the carriage on the stand.
  dBodyID RootBody() const { return stand ? stand->carriage : nullptr; }

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

void LegWorld::Impl::BuildBodies() {
  const std::vector<Eigen::Isometry3d> poses = LinkPoses(leg.links, LegAngles{});
  for (const BodyDescription& description : leg.bodies) {
    Body body{.link = description.link,
              .com_in_link = ToEigen(description.com_m),
              .mass_kg = description.mass_kg,
              .inertia_kg_m2 = ToEigen(description.inertia_kg_m2)};
    dMass mass;
    const Eigen::Matrix3d& in = body.inertia_kg_m2;
    dMassSetParameters(&mass, body.mass_kg, 0.0, 0.0, 0.0, in(0, 0), in(1, 1), in(2, 2), in(0, 1),
                       in(0, 2), in(1, 2));
    if (dMassCheck(&mass) == 0) {
      throw std::invalid_argument("link '" + leg.links[body.link].name +
                                  "': ODE rejects its combined mass");
    }
    body.id = dBodyCreate(world->get());
    dBodySetMass(body.id, &mass);
    const Eigen::Isometry3d& pose = poses[body.link];
    const Eigen::Vector3d com_world = pose * body.com_in_link;
    dBodySetPosition(body.id, com_world.x(), com_world.y(), com_world.z());
    SetRotation(body.id, pose.linear());
    bodies.push_back(body);
  }
}

void LegWorld::Impl::BuildHinges() {
  // Built at q = 0, which ODE takes as each hinge's zero angle. Attaching (child, parent) makes
  // ODE's angle the child's turn about the axis relative to the parent: the URDF's sign.
  for (std::size_t i = 1; i < leg.links.size(); ++i) {
    const LinkDescription& link = leg.links[i];
    if (link.joint < 0) {
      continue;
    }
    const JointDescription& joint = leg.joints[link.joint];
    const int parent_body = leg.links[link.parent].body;
    const dJointID hinge = dJointCreateHinge(world->get(), nullptr);
    dJointAttach(hinge, bodies[link.body].id,
                 parent_body >= 0 ? bodies[parent_body].id : RootBody());
    dJointSetHingeAnchor(hinge, joint.position_m[0], joint.position_m[1], joint.position_m[2]);
    dJointSetHingeAxis(hinge, joint.axis[0], joint.axis[1], joint.axis[2]);
    dJointSetHingeParam(hinge, dParamLoStop, joint.lower_rad - kStopMarginRad);
    dJointSetHingeParam(hinge, dParamHiStop, joint.upper_rad + kStopMarginRad);
    dJointSetHingeParam(hinge, dParamBounce, 0.0);
    dJointSetHingeParam(hinge, dParamFMax, 0.0);
    hinges[link.joint] = hinge;
  }
}

void LegWorld::Impl::BuildStand(const StandConfig& config) {
  const int foot_link = leg.FindLink(kFootLinkName);
  assert(foot_link > 0 && leg.links[foot_link].body >= 0 && "the description has a moving foot");
  const Body& foot_body = bodies[leg.links[foot_link].body];
  // The foot's centre relative to the body's centre of mass, in the body's (link) axes.
  const Eigen::Vector3d foot_offset_m =
      ToEigen(leg.links[foot_link].in_body.translation_m) - foot_body.com_in_link;
  stand = std::make_unique<Stand>(world->get(), config, leg.joints[kRotator].position_m[2],
                                  foot_body.id, foot_offset_m);
}

LegWorld::LegWorld(const LegDescription& leg, const StandConfig& stand)
    : impl_(std::make_unique<Impl>()) {
  CheckStructure(leg);
  impl_->leg = leg;
  EnsureOdeReady();
  impl_->world.emplace();
  dWorldSetGravity(impl_->world->get(), 0.0, 0.0, -kGravityMPerS2);
  impl_->BuildBodies();
  if (stand.enabled) impl_->BuildStand(stand);
  impl_->BuildHinges();
}

LegWorld::LegWorld(const std::string& urdf_path, const StandConfig& stand)
    : LegWorld(LoadLegDescription(urdf_path), stand) {}

LegWorld::~LegWorld() = default;
LegWorld::LegWorld(LegWorld&&) noexcept = default;
LegWorld& LegWorld::operator=(LegWorld&&) noexcept = default;

const JointDescription& LegWorld::joint(int joint) const { return impl_->leg.joints.at(joint); }

const LegDescription& LegWorld::description() const { return impl_->leg; }

LegAngles LegWorld::AnglesRad() const {
  LegAngles angles{};
  for (int j = 0; j < kLegJoints; ++j) {
    angles[j] = dJointGetHingeAngle(impl_->hinges[j]);
  }
  return angles;
}

LegAngles LegWorld::RatesRadPerS() const {
  LegAngles rates{};
  for (int j = 0; j < kLegJoints; ++j) {
    rates[j] = dJointGetHingeAngleRate(impl_->hinges[j]);
  }
  return rates;
}

void LegWorld::SetMotor(int joint, double speed_rad_per_s, double max_torque_nm) {
  assert(joint >= 0 && joint < kLegJoints && max_torque_nm >= 0.0);
  dJointSetHingeParam(impl_->hinges[joint], dParamVel, speed_rad_per_s);
  dJointSetHingeParam(impl_->hinges[joint], dParamFMax, max_torque_nm);
}

void LegWorld::Step(double dt_s) {
  // A world built on one thread may be stepped on another (a moved plant): ODE needs its
  // per-thread data there too. After the first call on a thread this is one flag test.
  EnsureOdeReady();
  try {
    if (impl_->stand) {
      impl_->stand->Step(impl_->world->get(), dt_s);
    } else {
      dWorldStep(impl_->world->get(), dt_s);
    }
  } catch (...) {  // an ODE error (EnsureOdeReady) left the step half done
    impl_->world->MarkBroken();
    throw;
  }
}

const StandState& LegWorld::stand_state() const {
  static const StandState kNone{};
  return impl_->stand ? impl_->stand->state : kNone;
}

bool LegWorld::has_stand() const { return impl_->stand != nullptr; }

void LegWorld::SetConfigurationRad(const LegAngles& q_rad) {
  const std::vector<Eigen::Isometry3d> poses = LinkPoses(impl_->leg.links, q_rad);
  // On the stand: the carriage on its stop, or as high as keeps the foot out of the floor.
  Eigen::Vector3d lift = Eigen::Vector3d::Zero();
  if (impl_->stand) {
    const int foot = impl_->leg.FindLink(kFootLinkName);
    lift.z() = impl_->stand->PlaceCarriage(poses[foot].translation().z());
  }
  for (const Impl::Body& body : impl_->bodies) {
    const Eigen::Isometry3d& pose = poses[body.link];
    const Eigen::Vector3d com_world = pose * body.com_in_link + lift;
    dBodySetPosition(body.id, com_world.x(), com_world.y(), com_world.z());
    SetRotation(body.id, pose.linear());
    dBodySetLinearVel(body.id, 0.0, 0.0, 0.0);
    dBodySetAngularVel(body.id, 0.0, 0.0, 0.0);
  }
}

std::array<double, 3> LegWorld::LinkOriginMm(std::string_view link_name) const {
  const int index = impl_->leg.FindLink(link_name);
  if (index < 0) {
    throw std::invalid_argument("link '" + std::string(link_name) + "' not found in the URDF");
  }
  const LinkDescription& link = impl_->leg.links[index];
  const Eigen::Isometry3d body_link_pose = link.body >= 0
                                               ? impl_->BodyLinkPose(impl_->bodies[link.body])
                                               : Eigen::Isometry3d::Identity();
  Eigen::Vector3d origin_mm = 1000.0 * (body_link_pose * ToEigen(link.in_body)).translation();
  // On the stand the body frame is the carriage's: the world frame raised by its height (and
  // moved along x and y with the sled, when there is one).
  if (impl_->stand) {
    origin_mm.z() -= 1000.0 * impl_->stand->CarriageZM();
    if (impl_->stand->has_sled()) {
      origin_mm.x() -= 1000.0 * impl_->stand->SledXM();
      origin_mm.y() -= 1000.0 * impl_->stand->SledYM();
    }
    if (link.body < 0) origin_mm = 1000.0 * ToEigen(link.in_body.translation_m);
  }
  return {origin_mm.x(), origin_mm.y(), origin_mm.z()};
}

double LegWorld::KineticEnergyJ() const {
  double energy = 0.0;
  for (const Impl::Body& body : impl_->bodies) {
    const Eigen::Vector3d velocity = FromOde(dBodyGetLinearVel(body.id));
    // The inertia is in link axes, which are the body's axes.
    const Eigen::Vector3d omega =
        RotationOf(body.id).transpose() * FromOde(dBodyGetAngularVel(body.id));
    energy +=
        0.5 * body.mass_kg * velocity.squaredNorm() + 0.5 * omega.dot(body.inertia_kg_m2 * omega);
  }
  if (impl_->stand) energy += impl_->stand->CarriageKineticEnergyJ();
  return energy;
}

double LegWorld::MechanicalEnergyJ() const {
  double potential = 0.0;
  for (const Impl::Body& body : impl_->bodies) {
    potential += body.mass_kg * kGravityMPerS2 * dBodyGetPosition(body.id)[2];
  }
  if (impl_->stand) {
    potential += impl_->stand->CarriagePotentialEnergyJ(kGravityMPerS2);
    potential += impl_->stand->SledSpringEnergyJ();
  }
  return KineticEnergyJ() + potential;
}

std::string LegWorld::StateProblem() const {
  if (impl_->stand) {
    std::string problem = impl_->stand->StateProblem();
    if (!problem.empty()) return problem;
  }
  for (const Impl::Body& body : impl_->bodies) {
    const dReal* values[] = {dBodyGetPosition(body.id), dBodyGetQuaternion(body.id),
                             dBodyGetLinearVel(body.id), dBodyGetAngularVel(body.id)};
    for (const dReal* v : values) {
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
        return "link '" + impl_->leg.links[body.link].name + "' has a non-finite pose or velocity";
      }
    }
  }
  for (int j = 0; j < kLegJoints; ++j) {
    const dJointID hinge = impl_->hinges[j];
    const double rate = dJointGetHingeAngleRate(hinge);
    if (!std::isfinite(dJointGetHingeAngle(hinge)) || !(std::abs(rate) <= kExplodedRateRadPerS)) {
      return "joint '" + impl_->leg.joints[j].name + "' turns at " + std::to_string(rate) +
             " rad/s (limit " + std::to_string(kExplodedRateRadPerS) + ")";
    }
    dVector3 anchor1;
    dVector3 anchor2;
    dJointGetHingeAnchor(hinge, anchor1);
    dJointGetHingeAnchor2(hinge, anchor2);
    const double gap_m = (FromOde(anchor1) - FromOde(anchor2)).norm();
    if (!(gap_m <= 1e-3)) {
      return "joint '" + impl_->leg.joints[j].name + "' came apart: its anchors are " +
             std::to_string(gap_m * 1000.0) + " mm apart";
    }
  }
  return {};
}

}  // namespace leglab::sim
