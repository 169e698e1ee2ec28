#include "leglab/sim/leg_world.h"
#include "leglab/core/units.h"

#include <console_bridge/console.h>
#include <ode/ode.h>
#include <ode/threading_impl.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cassert>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace leglab::sim {
namespace {

static_assert(std::is_same_v<dReal, double>, "leglab::sim needs ODE built in double precision");

// ODE's global state: initialised on first use, closed at exit. Each thread that steps a world
// needs its own ODE data.
void EnsureOdeReady() {
  struct Runtime {
    Runtime() { dInitODE2(0); }
    ~Runtime() { dCloseODE(); }
    Runtime(const Runtime&) = delete;
    Runtime& operator=(const Runtime&) = delete;
  };
  static Runtime runtime;
  thread_local const bool thread_ready = dAllocateODEDataForThread(dAllocateMaskAll) != 0;
  if (!thread_ready) {
    throw std::runtime_error("leglab::sim: ODE could not allocate thread data");
  }
}

// An ODE world with a threading implementation of its own. Without one, dWorldStep uses a
// process-wide default that crashes when worlds are stepped on parallel threads.
class OdeWorld {
 public:
  OdeWorld() : threading_(dThreadingAllocateSelfThreadedImplementation()), world_(dWorldCreate()) {
    if (threading_ == nullptr || world_ == nullptr) {
      Release();
      throw std::runtime_error("leglab::sim: ODE could not create a world");
    }
    dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_),
                                         threading_);
  }
  ~OdeWorld() { Release(); }
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;
  dWorldID get() const { return world_; }

 private:
  void Release() noexcept {
    if (world_ != nullptr) {
      dWorldSetStepThreadingImplementation(world_, nullptr, nullptr);
      dWorldDestroy(world_);  // and its bodies and joints
    }
    if (threading_ != nullptr) {
      dThreadingFreeImplementation(threading_);
    }
  }

  dThreadingImplementationID threading_;
  dWorldID world_;
};

// urdfdom reports parse errors through console_bridge instead of throwing: collect them while
// parsing so the exception can say why. console_bridge's handler is global, hence the mutex.
class CapturingOutput : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char* /*filename*/,
           int /*line*/) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) {
      if (!text_.empty()) {
        text_ += "; ";
      }
      text_ += text;
    }
  }
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

urdf::ModelInterfaceSharedPtr ParseUrdfFile(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw std::runtime_error("URDF file not found: '" + path + "'");
  }
  static std::mutex console_mutex;
  const std::lock_guard lock(console_mutex);
  CapturingOutput output;
  console_bridge::useOutputHandler(&output);
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  console_bridge::restorePreviousOutputHandler();
  if (!model) {
    throw std::runtime_error("failed to parse URDF file '" + path +
                             "': " + (output.text().empty() ? "unknown error" : output.text()));
  }
  return model;
}

Eigen::Isometry3d ToIsometry(const urdf::Pose& pose) {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  transform.linear() =
      Eigen::Quaterniond(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z)
          .normalized()
          .toRotationMatrix();
  transform.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return transform;
}

std::string Deg(double rad) { return std::to_string(RadToDeg(rad)); }

Eigen::Vector3d ToEigen(const dReal* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }

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

// Mass of one link's <inertial>, checked, as inertia about its centre of mass in link axes.
struct LinkMass {
  double mass_kg = 0.0;
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();              // in the link frame
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Identity();  // about com, link axes
};

LinkMass CheckedMass(const urdf::Link& link) {
  const urdf::Inertial& in = *link.inertial;
  const std::string where = "link '" + link.name + "': ";
  if (!std::isfinite(in.mass) || in.mass <= 0.0) {
    throw std::invalid_argument(where + "inertial mass must be > 0 kg, got " +
                                std::to_string(in.mass));
  }
  Eigen::Matrix3d inertia;
  inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  if (!inertia.allFinite()) {
    throw std::invalid_argument(where + "inertia has a non-finite entry");
  }
  const Eigen::Vector3d moments =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia, Eigen::EigenvaluesOnly)
          .eigenvalues();    // ascending
  std::string listed = "(";  // appended piecewise: GCC 12 misfires -Wrestrict on "(" + ...
  listed += std::to_string(moments[0]) + ", " + std::to_string(moments[1]) + ", " +
            std::to_string(moments[2]) + ")";
  if (moments[0] <= 0.0) {
    throw std::invalid_argument(where + "inertia must be positive definite, principal moments " +
                                listed + " kg m^2");
  }
  // A rigid body's largest principal moment cannot exceed the sum of the other two.
  if (moments[2] > (moments[0] + moments[1]) * (1.0 + 1e-9)) {
    throw std::invalid_argument(where + "inertia breaks the triangle inequality, principal " +
                                "moments " + listed + " kg m^2");
  }
  const Eigen::Isometry3d frame = ToIsometry(in.origin);
  LinkMass result;
  result.mass_kg = in.mass;
  result.com_m = frame.translation();
  result.inertia_kg_m2 = frame.linear() * inertia * frame.linear().transpose();
  return result;
}

// The sum of point-mass-and-inertia pieces, all in one frame, about their joint centre of mass.
LinkMass Combine(const std::vector<LinkMass>& pieces) {
  LinkMass total;
  total.inertia_kg_m2.setZero();
  for (const LinkMass& piece : pieces) {
    total.mass_kg += piece.mass_kg;
    total.com_m += piece.mass_kg * piece.com_m;
  }
  total.com_m /= total.mass_kg;
  for (const LinkMass& piece : pieces) {
    const Eigen::Vector3d d = piece.com_m - total.com_m;
    total.inertia_kg_m2 +=
        piece.inertia_kg_m2 + piece.mass_kg * (d.squaredNorm() * Eigen::Matrix3d::Identity() -
                                               d * d.transpose());  // parallel axes
  }
  return total;
}

}  // namespace

struct LegWorld::Impl {
  // One URDF link, in depth-first order from the root (index 0).
  struct Link {
    std::string name;
    int parent = -1;                                           // -1 for the root
    int joint = -1;                                            // kLegJointNames index, -1 if fixed
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();  // parent link -> joint frame
    Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();           // unit, joint frame
    int body = -1;                                             // ODE body it rides on; -1: world
    Eigen::Isometry3d in_body_link = Eigen::Isometry3d::Identity();  // in the body's link frame
  };
  // One ODE body: a link moved by a hinge, with its lumped fixed children.
  struct Body {
    dBodyID id = nullptr;
    int link = -1;                                          // the link whose frame it carries
    Eigen::Vector3d com_in_link = Eigen::Vector3d::Zero();  // body origin in that frame, m
    double mass_kg = 0.0;
    Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  // about com, link axes
  };

  std::optional<OdeWorld> world;  // created after the URDF checks, once ODE is ready
  std::vector<Link> links;
  std::vector<Body> bodies;
  std::array<dJointID, kLegJoints> hinges{};
  std::array<JointInfo, kLegJoints> joints;

  int FindLink(std::string_view name) const {
    for (std::size_t i = 0; i < links.size(); ++i) {
      if (links[i].name == name) {
        return static_cast<int>(i);
      }
    }
    return -1;
  }

  // Pose of every link in the world for joint angles q_rad, from the URDF alone.
  std::vector<Eigen::Isometry3d> LinkPoses(const LegAngles& q_rad) const {
    std::vector<Eigen::Isometry3d> poses(links.size(), Eigen::Isometry3d::Identity());
    for (std::size_t i = 1; i < links.size(); ++i) {
      const Link& link = links[i];
      poses[i] = poses[link.parent] * link.origin;
      if (link.joint >= 0) {
        poses[i].rotate(Eigen::AngleAxisd(q_rad[link.joint], link.axis));
      }
    }
    return poses;
  }

  // Pose of a body's link frame in the world, from ODE's state.
  Eigen::Isometry3d BodyLinkPose(const Body& body) const {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = RotationOf(body.id);
    pose.translation() = ToEigen(dBodyGetPosition(body.id)) - pose.linear() * body.com_in_link;
    return pose;
  }

  void ReadTree(const urdf::ModelInterface& model, const std::string& path);
  void CheckJoints(const urdf::ModelInterface& model, const std::string& path);
  void BuildBodies(const urdf::ModelInterface& model);
  void BuildHinges();
};

void LegWorld::Impl::ReadTree(const urdf::ModelInterface& model, const std::string& path) {
  const urdf::LinkConstSharedPtr root = model.getRoot();
  if (!root) {
    throw std::runtime_error("URDF file '" + path + "' has no root link");
  }
  // Depth-first, so every parent precedes its children.
  std::vector<std::pair<urdf::LinkConstSharedPtr, int>> stack{{root, -1}};
  while (!stack.empty()) {
    const auto [urdf_link, parent] = stack.back();
    stack.pop_back();
    Link link;
    link.name = urdf_link->name;
    link.parent = parent;
    if (const urdf::JointSharedPtr& joint = urdf_link->parent_joint) {
      link.origin = ToIsometry(joint->parent_to_joint_origin_transform);
      const Eigen::Vector3d axis(joint->axis.x, joint->axis.y, joint->axis.z);
      if (joint->type != urdf::Joint::FIXED) {
        int index = -1;
        for (int j = 0; j < kLegJoints; ++j) {
          if (kLegJointNames[j] == joint->name) {
            index = j;
          }
        }
        if (index < 0) {
          throw std::invalid_argument("joint '" + joint->name + "' in URDF '" + path +
                                      "' is movable, but leglab::sim drives only rotator, "
                                      "abductor and knee (make it fixed)");
        }
        if (axis.norm() < 1e-9) {
          throw std::invalid_argument("joint '" + joint->name + "': axis must be non-zero");
        }
        link.joint = index;
        link.axis = axis.normalized();
      }
    }
    links.push_back(link);
    const int self = static_cast<int>(links.size()) - 1;
    for (auto it = urdf_link->child_links.rbegin(); it != urdf_link->child_links.rend(); ++it) {
      stack.emplace_back(*it, self);
    }
  }
}

void LegWorld::Impl::CheckJoints(const urdf::ModelInterface& model, const std::string& path) {
  for (int j = 0; j < kLegJoints; ++j) {
    const std::string name(kLegJointNames[j]);
    const urdf::JointConstSharedPtr joint = model.getJoint(name);
    if (!joint) {
      std::string present;
      for (const auto& [joint_name, unused] : model.joints_) {
        present += present.empty() ? "" : ", ";
        present += joint_name;
      }
      throw std::invalid_argument("joint '" + name + "' not found in URDF '" + path +
                                  "' (it has: " + (present.empty() ? "none" : present) + ")");
    }
    if (joint->type != urdf::Joint::REVOLUTE) {
      throw std::invalid_argument("joint '" + name + "' must be revolute (with limits)");
    }
    if (joint->mimic) {
      throw std::invalid_argument("joint '" + name + "': mimic is not modelled");
    }
    if (joint->dynamics && (joint->dynamics->damping != 0.0 || joint->dynamics->friction != 0.0)) {
      throw std::invalid_argument("joint '" + name +
                                  "': <dynamics> damping and friction are not modelled by "
                                  "leglab::sim, give 0 or leave them out");
    }
    const urdf::JointLimits& limits = *joint->limits;  // urdfdom demands them for revolute
    const double stop_lo = limits.lower - kStopMarginRad;
    const double stop_hi = limits.upper + kStopMarginRad;
    if (!(limits.lower < limits.upper) || !(stop_lo > -std::numbers::pi) ||
        !(stop_hi < std::numbers::pi)) {
      throw std::invalid_argument("joint '" + name + "': limits [" + Deg(limits.lower) + ", " +
                                  Deg(limits.upper) +
                                  "] deg must be increasing and leave room for the mechanical "
                                  "stops 3 deg beyond them inside (-180, 180) deg");
    }
    if (!(limits.effort > 0.0)) {
      throw std::invalid_argument("joint '" + name + "': effort limit must be > 0 N m");
    }
    joints[j] = JointInfo{name, limits.lower, limits.upper, limits.effort, limits.velocity};
  }
  if (!model.getLink(std::string(kFootLinkName))) {
    throw std::invalid_argument("link '" + std::string(kFootLinkName) + "' not found in URDF '" +
                                path + "'");
  }
}

void LegWorld::Impl::BuildBodies(const urdf::ModelInterface& model) {
  const std::vector<Eigen::Isometry3d> poses = LinkPoses(LegAngles{});
  std::vector<std::vector<LinkMass>> pieces;
  for (std::size_t i = 1; i < links.size(); ++i) {
    Link& link = links[i];
    const Link& parent = links[link.parent];
    if (link.joint >= 0) {
      link.body = static_cast<int>(bodies.size());
      bodies.push_back(Body{.link = static_cast<int>(i)});
      pieces.emplace_back();
    } else {
      link.body = parent.body;
      link.in_body_link = parent.in_body_link * link.origin;
    }
    const urdf::LinkConstSharedPtr urdf_link = model.getLink(link.name);
    if (link.body >= 0 && urdf_link->inertial) {
      LinkMass mass = CheckedMass(*urdf_link);
      mass.com_m = link.in_body_link * mass.com_m;
      mass.inertia_kg_m2 =
          link.in_body_link.linear() * mass.inertia_kg_m2 * link.in_body_link.linear().transpose();
      pieces[link.body].push_back(mass);
    }
  }
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    Body& body = bodies[b];
    const Link& link = links[body.link];
    if (pieces[b].empty()) {
      throw std::invalid_argument("link '" + link.name + "' (moved by joint '" +
                                  joints[link.joint].name +
                                  "') has no <inertial>: the simulator needs its mass");
    }
    const LinkMass total = Combine(pieces[b]);
    body.com_in_link = total.com_m;
    body.mass_kg = total.mass_kg;
    body.inertia_kg_m2 = total.inertia_kg_m2;
    dMass mass;
    const Eigen::Matrix3d& in = total.inertia_kg_m2;
    dMassSetParameters(&mass, total.mass_kg, 0.0, 0.0, 0.0, in(0, 0), in(1, 1), in(2, 2), in(0, 1),
                       in(0, 2), in(1, 2));
    if (dMassCheck(&mass) == 0) {
      throw std::invalid_argument("link '" + link.name + "': ODE rejects its combined mass");
    }
    body.id = dBodyCreate(world->get());
    dBodySetMass(body.id, &mass);
    const Eigen::Isometry3d& pose = poses[body.link];
    const Eigen::Vector3d com_world = pose * body.com_in_link;
    dBodySetPosition(body.id, com_world.x(), com_world.y(), com_world.z());
    SetRotation(body.id, pose.linear());
  }
}

void LegWorld::Impl::BuildHinges() {
  // Built at q = 0, which ODE takes as each hinge's zero angle. Attaching (child, parent) makes
  // ODE's angle the child's turn about the axis relative to the parent: the URDF's sign.
  const std::vector<Eigen::Isometry3d> poses = LinkPoses(LegAngles{});
  for (std::size_t i = 1; i < links.size(); ++i) {
    const Link& link = links[i];
    if (link.joint < 0) {
      continue;
    }
    const int parent_body = links[link.parent].body;
    const dJointID hinge = dJointCreateHinge(world->get(), nullptr);
    dJointAttach(hinge, bodies[link.body].id, parent_body >= 0 ? bodies[parent_body].id : nullptr);
    const Eigen::Vector3d anchor = poses[i].translation();
    const Eigen::Vector3d axis = poses[i].linear() * link.axis;
    dJointSetHingeAnchor(hinge, anchor.x(), anchor.y(), anchor.z());
    dJointSetHingeAxis(hinge, axis.x(), axis.y(), axis.z());
    const JointInfo& info = joints[link.joint];
    dJointSetHingeParam(hinge, dParamLoStop, info.lower_rad - kStopMarginRad);
    dJointSetHingeParam(hinge, dParamHiStop, info.upper_rad + kStopMarginRad);
    dJointSetHingeParam(hinge, dParamBounce, 0.0);
    dJointSetHingeParam(hinge, dParamFMax, 0.0);
    hinges[link.joint] = hinge;
  }
}

LegWorld::LegWorld(const std::string& urdf_path) : impl_(std::make_unique<Impl>()) {
  const urdf::ModelInterfaceSharedPtr model = ParseUrdfFile(urdf_path);
  impl_->CheckJoints(*model, urdf_path);
  impl_->ReadTree(*model, urdf_path);
  EnsureOdeReady();
  impl_->world.emplace();
  dWorldSetGravity(impl_->world->get(), 0.0, 0.0, -kGravityMPerS2);
  impl_->BuildBodies(*model);
  impl_->BuildHinges();
}

LegWorld::~LegWorld() = default;
LegWorld::LegWorld(LegWorld&&) noexcept = default;
LegWorld& LegWorld::operator=(LegWorld&&) noexcept = default;

const JointInfo& LegWorld::joint(int joint) const { return impl_->joints.at(joint); }

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
  dWorldStep(impl_->world->get(), dt_s);
}

void LegWorld::SetConfigurationRad(const LegAngles& q_rad) {
  const std::vector<Eigen::Isometry3d> poses = impl_->LinkPoses(q_rad);
  for (const Impl::Body& body : impl_->bodies) {
    const Eigen::Isometry3d& pose = poses[body.link];
    const Eigen::Vector3d com_world = pose * body.com_in_link;
    dBodySetPosition(body.id, com_world.x(), com_world.y(), com_world.z());
    SetRotation(body.id, pose.linear());
    dBodySetLinearVel(body.id, 0.0, 0.0, 0.0);
    dBodySetAngularVel(body.id, 0.0, 0.0, 0.0);
  }
}

std::array<double, 3> LegWorld::LinkOriginMm(std::string_view link_name) const {
  const int index = impl_->FindLink(link_name);
  if (index < 0) {
    throw std::invalid_argument("link '" + std::string(link_name) + "' not found in the URDF");
  }
  const Impl::Link& link = impl_->links[index];
  const Eigen::Isometry3d body_link_pose = link.body >= 0
                                               ? impl_->BodyLinkPose(impl_->bodies[link.body])
                                               : Eigen::Isometry3d::Identity();
  const Eigen::Vector3d origin_mm = 1000.0 * (body_link_pose * link.in_body_link).translation();
  return {origin_mm.x(), origin_mm.y(), origin_mm.z()};
}

double LegWorld::KineticEnergyJ() const {
  double energy = 0.0;
  for (const Impl::Body& body : impl_->bodies) {
    const Eigen::Vector3d velocity = ToEigen(dBodyGetLinearVel(body.id));
    // The inertia is in link axes, which are the body's axes.
    const Eigen::Vector3d omega =
        RotationOf(body.id).transpose() * ToEigen(dBodyGetAngularVel(body.id));
    energy +=
        0.5 * body.mass_kg * velocity.squaredNorm() + 0.5 * omega.dot(body.inertia_kg_m2 * omega);
  }
  return energy;
}

double LegWorld::MechanicalEnergyJ() const {
  double potential = 0.0;
  for (const Impl::Body& body : impl_->bodies) {
    potential += body.mass_kg * kGravityMPerS2 * dBodyGetPosition(body.id)[2];
  }
  return KineticEnergyJ() + potential;
}

std::string LegWorld::StateProblem() const {
  for (const Impl::Body& body : impl_->bodies) {
    const dReal* values[] = {dBodyGetPosition(body.id), dBodyGetQuaternion(body.id),
                             dBodyGetLinearVel(body.id), dBodyGetAngularVel(body.id)};
    for (const dReal* v : values) {
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) {
        return "link '" + impl_->links[body.link].name + "' has a non-finite pose or velocity";
      }
    }
  }
  for (int j = 0; j < kLegJoints; ++j) {
    const dJointID hinge = impl_->hinges[j];
    const double rate = dJointGetHingeAngleRate(hinge);
    if (!std::isfinite(dJointGetHingeAngle(hinge)) || !(std::abs(rate) <= kExplodedRateRadPerS)) {
      return "joint '" + impl_->joints[j].name + "' turns at " + std::to_string(rate) +
             " rad/s (limit " + std::to_string(kExplodedRateRadPerS) + ")";
    }
    dVector3 anchor1;
    dVector3 anchor2;
    dJointGetHingeAnchor(hinge, anchor1);
    dJointGetHingeAnchor2(hinge, anchor2);
    const double gap_m = (ToEigen(anchor1) - ToEigen(anchor2)).norm();
    if (!(gap_m <= 1e-3)) {
      return "joint '" + impl_->joints[j].name + "' came apart: its anchors are " +
             std::to_string(gap_m * 1000.0) + " mm apart";
    }
  }
  return {};
}

}  // namespace leglab::sim
