#include <ode/ode.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "leglab/sim/leg_world.h"
#include "ode_stand.h"

namespace leglab::sim {
namespace {

// An ODE vector (dVector3 or a body's position, velocity) as Eigen.
Eigen::Vector3d FromOde(const dReal* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

}  // namespace

Stand::Stand(dWorldID world, const StandConfig& stand_config, double shoulder_z_m,
             dBodyID foot_body, const Eigen::Vector3d& foot_offset_m)
    : config(stand_config) {
  BuildCarriage(world);
  if (config.sled_stiffness_n_per_m > 0.0) {
    BuildSled(world);
  } else {
    BuildRail(world);
  }
  BuildFloorAndFoot(shoulder_z_m, foot_body, foot_offset_m);
}

Stand::~Stand() {
  // The bodies and joints go with the world; the space (with its geoms) and the group here.
  if (contacts != nullptr) dJointGroupDestroy(contacts);
  if (space != nullptr) dSpaceDestroy(space);
}

void Stand::BuildCarriage(dWorldID world) {
  // The carriage: the root link's frame, carrying the load. The slider (or the sled's angular
  // motor) keeps it upright, so its inertia only has to be valid: a solid sphere of 5 cm radius.
  carriage = dBodyCreate(world);
  dMass mass;
  dMassSetSphereTotal(&mass, config.load_kg, 0.05);
  dBodySetMass(carriage, &mass);
  dBodySetPosition(carriage, 0.0, 0.0, 0.0);
}

void Stand::BuildSled(dWorldID world) {
  // The sled: the rail rides on a cross slide, so the carriage moves along x, y and z but
  // never turns. Built from the fewest constraint rows, as cheap as the slider it replaces (see
  // docs/design/stand.md): an angular motor holding the carriage's angular velocity at zero
  // about the world's three axes (unbounded torque), and a linear motor along x and y whose rows
  // are the sled's spring-damper, set each step by JoinSled (which knows h); integrated
  // implicitly, the spring cannot feed energy into the walk whatever k and c are. The rail's
  // stop is a contact with the frame (JoinSled).
  upright = dJointCreateAMotor(world, nullptr);
  dJointAttach(upright, carriage, nullptr);
  dJointSetAMotorMode(upright, dAMotorUser);
  dJointSetAMotorNumAxes(upright, 3);
  dJointSetAMotorAxis(upright, 0, 0, 1.0, 0.0, 0.0);
  dJointSetAMotorAxis(upright, 1, 0, 0.0, 1.0, 0.0);
  dJointSetAMotorAxis(upright, 2, 0, 0.0, 0.0, 1.0);
  for (const int param : {dParamFMax, dParamFMax2, dParamFMax3}) {
    dJointSetAMotorParam(upright, param, dInfinity);
  }
  sled = dJointCreateLMotor(world, nullptr);
  dJointAttach(sled, carriage, nullptr);
  dJointSetLMotorNumAxes(sled, 2);
  dJointSetLMotorAxis(sled, 0, 0, 1.0, 0.0, 0.0);
  dJointSetLMotorAxis(sled, 1, 0, 0.0, 1.0, 0.0);
  dJointSetLMotorParam(sled, dParamFMax, dInfinity);
  dJointSetLMotorParam(sled, dParamFMax2, dInfinity);
}

void Stand::BuildRail(dWorldID world) {
  // The rail: a vertical slider to the static world. Its position is the carriage's height
  // (zero where it was attached, at the walking height).
  rail = dJointCreateSlider(world, nullptr);
  dJointAttach(rail, carriage, nullptr);
  dJointSetSliderAxis(rail, 0.0, 0.0, 1.0);
  dJointSetSliderParam(rail, dParamLoStop, -config.stop_below_shoulder_mm / 1000.0);
  dJointSetSliderParam(rail, dParamBounce, 0.0);
}

void Stand::BuildFloorAndFoot(double shoulder_z_m, dBodyID foot_body,
                              const Eigen::Vector3d& foot_offset_m) {
  // The floor and the ball of the foot, in one collision space.
  floor_z_m = shoulder_z_m - (config.ground_below_shoulder_mm + config.foot_radius_mm) / 1000.0;
  space = dSimpleSpaceCreate(nullptr);
  floor = dCreatePlane(space, 0.0, 0.0, 1.0, floor_z_m);
  foot = dCreateSphere(space, config.foot_radius_mm / 1000.0);
  dGeomSetBody(foot, foot_body);
  dGeomSetOffsetPosition(foot, foot_offset_m.x(), foot_offset_m.y(), foot_offset_m.z());
  contacts = dJointGroupCreate(0);
}

void Stand::Step(dWorldID world, double dt_s) {
  CollideAndJoin(world, dt_s);
  if (has_sled()) JoinSled(world, dt_s);
  dWorldStep(world, dt_s);
  MeasureContacts(dt_s);
}

void Stand::CollideAndJoin(dWorldID world, double dt_s) {
  contact_count = 0;
  // The space's only pair is the foot and the floor; the callback generates their contacts.
  dSpaceCollide(space, this, [](void* data, dGeomID a, dGeomID b) {
    auto* stand_data = static_cast<Stand*>(data);
    const int room = Stand::kMaxContacts - stand_data->contact_count;
    if (room <= 0) return;
    const int found =
        dCollide(a, b, room, &stand_data->geoms[stand_data->contact_count], sizeof(dContactGeom));
    stand_data->contact_count += found;
  });
  // Spring-damper k, c as ERP and CFM for this step (ODE manual, "How to use ERP and CFM").
  const double k = config.contact_stiffness_n_per_m;
  const double c = config.contact_damping_n_s_per_m;
  const double erp = dt_s * k / (dt_s * k + c);
  const double cfm = 1.0 / (dt_s * k + c);
  const dBodyID foot_body = dGeomGetBody(foot);
  for (int i = 0; i < contact_count; ++i) {
    dContact contact{};
    contact.geom = geoms[i];
    // dCollide's normal points into the first geom; the joint wants it pointing at body 1.
    if (contact.geom.g1 != foot) {
      for (int axis = 0; axis < 3; ++axis) contact.geom.normal[axis] *= -1.0;
      std::swap(contact.geom.g1, contact.geom.g2);
    }
    contact.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
    contact.surface.mu = config.friction;
    if (config.belt_speed_mm_per_s != 0.0) {
      // The treadmill: friction drives the foot's contact point towards the belt's velocity
      // (ODE's surface motion along friction direction 1, x).
      contact.surface.mode |= dContactFDir1 | dContactMotion1;
      contact.fdir1[0] = 1.0;
      contact.fdir1[1] = 0.0;
      contact.fdir1[2] = 0.0;
      contact.surface.motion1 = -config.belt_speed_mm_per_s / 1000.0;
    }
    contact.surface.soft_erp = erp;
    contact.surface.soft_cfm = cfm;
    geoms[i] = contact.geom;
    const dJointID joint = dJointCreateContact(world, contacts, &contact);
    dJointAttach(joint, foot_body, nullptr);
    feedback[i] = dJointFeedback{};
    dJointSetFeedback(joint, &feedback[i]);
  }
}

void Stand::JoinSled(dWorldID world, double dt_s) {
  // The spring-damper's rows for this step: ERP = h k / (h k + c), CFM = 1 / (h k + c) (ODE
  // manual, "How to use ERP and CFM"), as a motor row: speed -(ERP / h) x, force unbounded.
  const double k = config.sled_stiffness_n_per_m;
  const double c = config.sled_damping_n_s_per_m;
  const double erp_per_s = k / (dt_s * k + c);
  const double cfm = 1.0 / (dt_s * k + c);
  const dReal* position = dBodyGetPosition(carriage);
  dJointSetLMotorParam(sled, dParamVel, -erp_per_s * position[0]);
  dJointSetLMotorParam(sled, dParamVel2, -erp_per_s * position[1]);
  dJointSetLMotorParam(sled, dParamCFM, cfm);
  dJointSetLMotorParam(sled, dParamCFM2, cfm);
  // The rail's lower stop, while the carriage is on it: a frictionless contact with the frame,
  // one row pushing up only, with the world's ERP and CFM as the slider's stop had.
  const double below_stop_m = -config.stop_below_shoulder_mm / 1000.0 - position[2];
  if (below_stop_m >= 0.0) {
    dContact stop{};
    stop.surface.mode = 0;
    stop.surface.mu = 0.0;
    stop.geom.pos[0] = position[0];
    stop.geom.pos[1] = position[1];
    stop.geom.pos[2] = position[2];
    stop.geom.normal[2] = 1.0;  // pointing at the carriage, body 1
    stop.geom.depth = below_stop_m;
    dJointAttach(dJointCreateContact(world, contacts, &stop), carriage, nullptr);
  }
}

void Stand::MeasureContacts(double dt_s) {
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  const dBodyID foot_body = dGeomGetBody(foot);
  for (int i = 0; i < contact_count; ++i) {
    // f1: the contact's force on body 1, the foot.
    const Eigen::Vector3d f = FromOde(feedback[i].f1);
    force += f;
    const Eigen::Vector3d normal(0.0, 0.0, 1.0);  // the floor's
    if (f.dot(normal) > LegWorld::kLoadedContactN) {
      const dContactGeom& g = geoms[i];
      dVector3 velocity;
      dBodyGetPointVel(foot_body, g.pos[0], g.pos[1], g.pos[2], velocity);
      // Relative to the belt's surface, which moves backward at the belt speed.
      const Eigen::Vector3d v =
          FromOde(velocity) + Eigen::Vector3d(config.belt_speed_mm_per_s / 1000.0, 0.0, 0.0);
      state.slip_mm += 1000.0 * (v - v.dot(normal) * normal).norm() * dt_s;
    }
  }
  dJointGroupEmpty(contacts);
  contact_count = 0;
  state.contact_force_n = {force.x(), force.y(), force.z()};
  state.carriage_z_mm = 1000.0 * CarriageZM();
  state.sled_x_mm = 1000.0 * SledXM();
  state.sled_y_mm = 1000.0 * SledYM();
}

double Stand::PlaceCarriage(double foot_z_m) {
  const double touching_z_m = floor_z_m + config.foot_radius_mm / 1000.0 - foot_z_m;
  const double lift_z_m = std::max(-config.stop_below_shoulder_mm / 1000.0, touching_z_m);
  dBodySetPosition(carriage, 0.0, 0.0, lift_z_m);
  if (has_sled()) {
    dMatrix3 upright_rotation;
    dRSetIdentity(upright_rotation);
    dBodySetRotation(carriage, upright_rotation);
  }
  dBodySetLinearVel(carriage, 0.0, 0.0, 0.0);
  dBodySetAngularVel(carriage, 0.0, 0.0, 0.0);
  state.contact_force_n = {0.0, 0.0, 0.0};
  state.carriage_z_mm = 1000.0 * lift_z_m;
  state.sled_x_mm = 0.0;
  state.sled_y_mm = 0.0;
  return lift_z_m;
}

double Stand::CarriageKineticEnergyJ() const {
  return 0.5 * config.load_kg * FromOde(dBodyGetLinearVel(carriage)).squaredNorm();
}

double Stand::CarriagePotentialEnergyJ(double gravity_m_per_s2) const {
  return config.load_kg * gravity_m_per_s2 * CarriageZM();
}

double Stand::SledSpringEnergyJ() const {
  const double x_m = SledXM();
  const double y_m = SledYM();
  return 0.5 * config.sled_stiffness_n_per_m * (x_m * x_m + y_m * y_m);
}

std::string Stand::StateProblem() const {
  const dReal* p = dBodyGetPosition(carriage);
  const dReal* v = dBodyGetLinearVel(carriage);
  if (!std::isfinite(p[2]) || !std::isfinite(v[2])) {
    return "the stand's carriage has a non-finite height or speed";
  }
  if (!std::isfinite(p[0]) || !std::isfinite(v[0]) || !std::isfinite(p[1]) ||
      !std::isfinite(v[1])) {
    return "the stand's sled has a non-finite position or speed";
  }
  return {};
}

}  // namespace leglab::sim
