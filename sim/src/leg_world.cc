#include "leglab/sim/leg_world.h"

#include <ode/ode.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "link_poses.h"
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

// The test stand's ODE objects: the carriage on its rail, the floor and the foot sphere in a
// collision space, and the joint group that holds one step's contacts.
struct Stand {
  static constexpr int kMaxContacts = 4;  // a sphere on a plane gives one

  StandConfig config;
  dBodyID carriage = nullptr;
  dJointID rail = nullptr;
  // With the sled (StandConfig::sled_stiffness_n_per_m > 0) the carriage has no slider: an
  // angular motor holds its rotation (3 rows), a linear motor along x and y carries the sled's
  // spring-damper (2 rows), and the rail's stop is a one-row contact made while the carriage
  // is on it: as many constraint rows as the slider and its stop, so the stand costs no more.
  dJointID upright = nullptr;
  dJointID sled = nullptr;
  bool has_sled() const { return sled != nullptr; }
  dSpaceID space = nullptr;
  dGeomID floor = nullptr;
  dGeomID foot = nullptr;
  dJointGroupID contacts = nullptr;
  std::array<dJointFeedback, kMaxContacts> feedback{};
  std::array<dContactGeom, kMaxContacts> geoms{};
  int contact_count = 0;
  double floor_z_m = 0.0;  // the floor plane's height in the world frame
  StandState state;

  Stand() = default;
  Stand(const Stand&) = delete;
  Stand& operator=(const Stand&) = delete;
  ~Stand() {
    // The bodies and joints go with the world; the space (with its geoms) and the group here.
    if (contacts != nullptr) dJointGroupDestroy(contacts);
    if (space != nullptr) dSpaceDestroy(space);
  }

  double CarriageZM() const { return dBodyGetPosition(carriage)[2]; }
  // The sled's (and so the carriage's) position along x and y from its spring's rest, m; 0
  // without a sled.
  double SledXM() const { return has_sled() ? dBodyGetPosition(carriage)[0] : 0.0; }
  double SledYM() const { return has_sled() ? dBodyGetPosition(carriage)[1] : 0.0; }
};

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
  void CollideAndJoin(double dt_s);
  void JoinSled(double dt_s);
  void MeasureContacts(double dt_s);
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
  stand = std::make_unique<Stand>();
  Stand& s = *stand;
  s.config = config;
  // The carriage: the root link's frame, carrying the load. The slider (or the sled's angular
  // motor) keeps it upright, so its inertia only has to be valid: a solid sphere of 5 cm radius.
  s.carriage = dBodyCreate(world->get());
  dMass mass;
  dMassSetSphereTotal(&mass, config.load_kg, 0.05);
  dBodySetMass(s.carriage, &mass);
  dBodySetPosition(s.carriage, 0.0, 0.0, 0.0);
  if (config.sled_stiffness_n_per_m > 0.0) {
    // The sled: the rail rides on a cross slide, so the carriage moves along x, y and z but
    // never turns. Built from the fewest constraint rows rather than as a chain of slider
    // bodies (which tripled the physics step's cost): an angular motor holding the carriage's
    // angular velocity at zero about the world's three axes (unbounded torque; the slider's
    // rotation rows did the same), and a linear motor along x and y whose rows are the
    // sled's spring-damper, the very rows a soft stop at 0 would make (ODE manual, "How to
    // use ERP and CFM"): speed -(ERP / h) x and CFM = 1 / (h k + c), with ERP = h k / (h k + c),
    // set in Step, which knows h. Integrated implicitly, the spring cannot feed energy into
    // the walk whatever k and c are. The rail's stop is a contact with the frame (Step).
    s.upright = dJointCreateAMotor(world->get(), nullptr);
    dJointAttach(s.upright, s.carriage, nullptr);
    dJointSetAMotorMode(s.upright, dAMotorUser);
    dJointSetAMotorNumAxes(s.upright, 3);
    dJointSetAMotorAxis(s.upright, 0, 0, 1.0, 0.0, 0.0);
    dJointSetAMotorAxis(s.upright, 1, 0, 0.0, 1.0, 0.0);
    dJointSetAMotorAxis(s.upright, 2, 0, 0.0, 0.0, 1.0);
    for (const int param : {dParamFMax, dParamFMax2, dParamFMax3}) {
      dJointSetAMotorParam(s.upright, param, dInfinity);
    }
    s.sled = dJointCreateLMotor(world->get(), nullptr);
    dJointAttach(s.sled, s.carriage, nullptr);
    dJointSetLMotorNumAxes(s.sled, 2);
    dJointSetLMotorAxis(s.sled, 0, 0, 1.0, 0.0, 0.0);
    dJointSetLMotorAxis(s.sled, 1, 0, 0.0, 1.0, 0.0);
    dJointSetLMotorParam(s.sled, dParamFMax, dInfinity);
    dJointSetLMotorParam(s.sled, dParamFMax2, dInfinity);
  } else {
    // The rail: a vertical slider to the static world. Its position is the carriage's height
    // (zero where it was attached, at the walking height).
    s.rail = dJointCreateSlider(world->get(), nullptr);
    dJointAttach(s.rail, s.carriage, nullptr);
    dJointSetSliderAxis(s.rail, 0.0, 0.0, 1.0);
    dJointSetSliderParam(s.rail, dParamLoStop, -config.stop_below_shoulder_mm / 1000.0);
    dJointSetSliderParam(s.rail, dParamBounce, 0.0);
  }
  // The floor and the ball of the foot, in one collision space.
  const double shoulder_z_m = leg.joints[kRotator].position_m[2];
  s.floor_z_m = shoulder_z_m - (config.ground_below_shoulder_mm + config.foot_radius_mm) / 1000.0;
  s.space = dSimpleSpaceCreate(nullptr);
  s.floor = dCreatePlane(s.space, 0.0, 0.0, 1.0, s.floor_z_m);
  s.foot = dCreateSphere(s.space, config.foot_radius_mm / 1000.0);
  const Body& foot_body = bodies[leg.links[foot_link].body];
  dGeomSetBody(s.foot, foot_body.id);
  // The foot's centre relative to the body's centre of mass, in the body's (link) axes.
  const Eigen::Vector3d offset =
      ToEigen(leg.links[foot_link].in_body.translation_m) - foot_body.com_in_link;
  dGeomSetOffsetPosition(s.foot, offset.x(), offset.y(), offset.z());
  s.contacts = dJointGroupCreate(0);
}

void LegWorld::Impl::CollideAndJoin(double dt_s) {
  Stand& s = *stand;
  s.contact_count = 0;
  // The space's only pair is the foot and the floor; the callback generates their contacts.
  dSpaceCollide(s.space, &s, [](void* data, dGeomID a, dGeomID b) {
    auto* stand_data = static_cast<Stand*>(data);
    const int room = Stand::kMaxContacts - stand_data->contact_count;
    if (room <= 0) return;
    const int found =
        dCollide(a, b, room, &stand_data->geoms[stand_data->contact_count], sizeof(dContactGeom));
    stand_data->contact_count += found;
  });
  // Spring-damper k, c as ERP and CFM for this step (ODE manual, "How to use ERP and CFM").
  const double k = s.config.contact_stiffness_n_per_m;
  const double c = s.config.contact_damping_n_s_per_m;
  const double erp = dt_s * k / (dt_s * k + c);
  const double cfm = 1.0 / (dt_s * k + c);
  const dBodyID foot_body = dGeomGetBody(s.foot);
  for (int i = 0; i < s.contact_count; ++i) {
    dContact contact{};
    contact.geom = s.geoms[i];
    // dCollide's normal points into the first geom; the joint wants it pointing at body 1.
    if (contact.geom.g1 != s.foot) {
      for (int axis = 0; axis < 3; ++axis) contact.geom.normal[axis] *= -1.0;
      std::swap(contact.geom.g1, contact.geom.g2);
    }
    contact.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
    contact.surface.mu = s.config.friction;
    if (s.config.belt_speed_mm_per_s != 0.0) {
      // The treadmill: friction drives the foot's contact point towards the belt's velocity
      // (ODE's surface motion along friction direction 1, x).
      contact.surface.mode |= dContactFDir1 | dContactMotion1;
      contact.fdir1[0] = 1.0;
      contact.fdir1[1] = 0.0;
      contact.fdir1[2] = 0.0;
      contact.surface.motion1 = -s.config.belt_speed_mm_per_s / 1000.0;
    }
    contact.surface.soft_erp = erp;
    contact.surface.soft_cfm = cfm;
    s.geoms[i] = contact.geom;
    const dJointID joint = dJointCreateContact(world->get(), s.contacts, &contact);
    dJointAttach(joint, foot_body, nullptr);
    s.feedback[i] = dJointFeedback{};
    dJointSetFeedback(joint, &s.feedback[i]);
  }
}

void LegWorld::Impl::JoinSled(double dt_s) {
  Stand& s = *stand;
  // The spring-damper's rows for this step: ERP = h k / (h k + c), CFM = 1 / (h k + c) (ODE
  // manual, "How to use ERP and CFM"), as a motor row: speed -(ERP / h) x, force unbounded.
  const double k = s.config.sled_stiffness_n_per_m;
  const double c = s.config.sled_damping_n_s_per_m;
  const double erp_per_s = k / (dt_s * k + c);
  const double cfm = 1.0 / (dt_s * k + c);
  const dReal* position = dBodyGetPosition(s.carriage);
  dJointSetLMotorParam(s.sled, dParamVel, -erp_per_s * position[0]);
  dJointSetLMotorParam(s.sled, dParamVel2, -erp_per_s * position[1]);
  dJointSetLMotorParam(s.sled, dParamCFM, cfm);
  dJointSetLMotorParam(s.sled, dParamCFM2, cfm);
  // The rail's lower stop, while the carriage is on it: a frictionless contact with the frame,
  // one row pushing up only, with the world's ERP and CFM as the slider's stop had.
  const double below_stop_m = -s.config.stop_below_shoulder_mm / 1000.0 - position[2];
  if (below_stop_m >= 0.0) {
    dContact stop{};
    stop.surface.mode = 0;
    stop.surface.mu = 0.0;
    stop.geom.pos[0] = position[0];
    stop.geom.pos[1] = position[1];
    stop.geom.pos[2] = position[2];
    stop.geom.normal[2] = 1.0;  // pointing at the carriage, body 1
    stop.geom.depth = below_stop_m;
    dJointAttach(dJointCreateContact(world->get(), s.contacts, &stop), s.carriage, nullptr);
  }
}

void LegWorld::Impl::MeasureContacts(double dt_s) {
  Stand& s = *stand;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  const dBodyID foot_body = dGeomGetBody(s.foot);
  for (int i = 0; i < s.contact_count; ++i) {
    // f1: the contact's force on body 1, the foot.
    const Eigen::Vector3d f = FromOde(s.feedback[i].f1);
    force += f;
    const Eigen::Vector3d normal(0.0, 0.0, 1.0);  // the floor's
    if (f.dot(normal) > kLoadedContactN) {
      const dContactGeom& g = s.geoms[i];
      dVector3 velocity;
      dBodyGetPointVel(foot_body, g.pos[0], g.pos[1], g.pos[2], velocity);
      // Relative to the belt's surface, which moves backward at the belt speed.
      const Eigen::Vector3d v =
          FromOde(velocity) + Eigen::Vector3d(s.config.belt_speed_mm_per_s / 1000.0, 0.0, 0.0);
      s.state.slip_mm += 1000.0 * (v - v.dot(normal) * normal).norm() * dt_s;
    }
  }
  dJointGroupEmpty(s.contacts);
  s.contact_count = 0;
  s.state.contact_force_n = {force.x(), force.y(), force.z()};
  s.state.carriage_z_mm = 1000.0 * s.CarriageZM();
  s.state.sled_x_mm = 1000.0 * s.SledXM();
  s.state.sled_y_mm = 1000.0 * s.SledYM();
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
  if (!impl_->stand) {
    dWorldStep(impl_->world->get(), dt_s);
    return;
  }
  impl_->CollideAndJoin(dt_s);
  if (impl_->stand->has_sled()) impl_->JoinSled(dt_s);
  dWorldStep(impl_->world->get(), dt_s);
  impl_->MeasureContacts(dt_s);
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
  if (Stand* s = impl_->stand.get()) {
    const int foot = impl_->leg.FindLink(kFootLinkName);
    const double foot_z_m = poses[foot].translation().z();
    const double touching_z_m = s->floor_z_m + s->config.foot_radius_mm / 1000.0 - foot_z_m;
    lift.z() = std::max(-s->config.stop_below_shoulder_mm / 1000.0, touching_z_m);
    dBodySetPosition(s->carriage, 0.0, 0.0, lift.z());
    if (s->has_sled()) SetRotation(s->carriage, Eigen::Matrix3d::Identity());
    dBodySetLinearVel(s->carriage, 0.0, 0.0, 0.0);
    dBodySetAngularVel(s->carriage, 0.0, 0.0, 0.0);
    s->state.contact_force_n = {0.0, 0.0, 0.0};
    s->state.carriage_z_mm = 1000.0 * lift.z();
    s->state.sled_x_mm = 0.0;
    s->state.sled_y_mm = 0.0;
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
  if (impl_->stand) {
    // The carriage only slides: translation alone.
    energy += 0.5 * impl_->stand->config.load_kg *
              FromOde(dBodyGetLinearVel(impl_->stand->carriage)).squaredNorm();
  }
  return energy;
}

double LegWorld::MechanicalEnergyJ() const {
  double potential = 0.0;
  for (const Impl::Body& body : impl_->bodies) {
    potential += body.mass_kg * kGravityMPerS2 * dBodyGetPosition(body.id)[2];
  }
  if (impl_->stand) {
    potential += impl_->stand->config.load_kg * kGravityMPerS2 * impl_->stand->CarriageZM();
    // The sled's spring (zero without a sled).
    const double x_m = impl_->stand->SledXM();
    const double y_m = impl_->stand->SledYM();
    potential += 0.5 * impl_->stand->config.sled_stiffness_n_per_m * (x_m * x_m + y_m * y_m);
  }
  return KineticEnergyJ() + potential;
}

std::string LegWorld::StateProblem() const {
  if (impl_->stand) {
    const dReal* p = dBodyGetPosition(impl_->stand->carriage);
    const dReal* v = dBodyGetLinearVel(impl_->stand->carriage);
    if (!std::isfinite(p[2]) || !std::isfinite(v[2])) {
      return "the stand's carriage has a non-finite height or speed";
    }
    if (!std::isfinite(p[0]) || !std::isfinite(v[0]) || !std::isfinite(p[1]) ||
        !std::isfinite(v[1])) {
      return "the stand's sled has a non-finite position or speed";
    }
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
