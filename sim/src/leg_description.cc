#include "leglab/sim/leg_description.h"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "link_poses.h"

namespace leglab::sim {
namespace {

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
  // A cycle of links (a hostile URDF, refused by CheckReachedFromRoot) is a cycle of urdfdom's
  // shared pointers: untie every link from its children when the model is released, so that
  // it is freed all the same.
  return {model.get(), [model](urdf::ModelInterface* m) mutable {
            for (auto& [name, link] : m->links_) {
              link->child_links.clear();
              link->child_joints.clear();
              link->parent_joint.reset();
            }
            model.reset();
          }};
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

// A number as a reader wants it: 1e-30, 0.0001, 100 (std::to_string would print 0.000000).
std::string Num(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// "urdf '<path>': <item> <what>", one line: the message of every physical-range check.
[[noreturn]] void Refuse(const std::string& path, const std::string& item,
                         const std::string& what) {
  throw std::invalid_argument("urdf '" + path + "': " + item + " " + what);
}

void CheckInRange(const std::string& path, const std::string& item, const std::string& field,
                  double value, const KeyDoc& doc) {
  if (const std::string problem = KeyValueProblem(value, doc); !problem.empty()) {
    Refuse(path, item, field + " must be " + problem + ", got " + Num(value));
  }
}

// An <origin>: finite, and no farther from its frame than a leg's part can be.
void CheckOrigin(const std::string& path, const std::string& item, const std::string& field,
                 const urdf::Pose& pose) {
  const Eigen::Vector3d xyz(pose.position.x, pose.position.y, pose.position.z);
  const Eigen::Vector4d rotation(pose.rotation.x, pose.rotation.y, pose.rotation.z,
                                 pose.rotation.w);
  if (!xyz.allFinite() || !rotation.allFinite()) {
    Refuse(path, item,
           field + " must be finite, got xyz (" + Num(xyz.x()) + ", " + Num(xyz.y()) + ", " +
               Num(xyz.z()) + ")");
  }
  CheckInRange(path, item, field + " offset", xyz.norm(), kOriginOffsetDoc);
}

// Mass of one link's <inertial>, checked, as inertia about its centre of mass in link axes.
struct LinkMass {
  double mass_kg = 0.0;
  Eigen::Vector3d com_m = Eigen::Vector3d::Zero();              // in the link frame
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Identity();  // about com, link axes
};

LinkMass CheckedMass(const urdf::Link& link, const std::string& path) {
  const urdf::Inertial& in = *link.inertial;
  const std::string item = "link '" + link.name + "'";
  CheckInRange(path, item, "mass", in.mass, kLinkMassDoc);
  CheckOrigin(path, item, "inertial origin", in.origin);
  Eigen::Matrix3d inertia;
  inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  if (!inertia.allFinite()) {
    Refuse(path, item, "inertia has a non-finite entry");
  }
  const Eigen::Vector3d moments =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia, Eigen::EigenvaluesOnly)
          .eigenvalues();    // ascending
  std::string listed = "(";  // appended piecewise: GCC 12 misfires -Wrestrict on "(" + ...
  listed += Num(moments[0]) + ", " + Num(moments[1]) + ", " + Num(moments[2]) + ")";
  if (moments[0] <= 0.0) {
    Refuse(path, item,
           "inertia must be positive definite, principal moments " + listed + " kg m^2");
  }
  CheckInRange(path, item, "inertia's least principal moment", moments[0], kPrincipalInertiaDoc);
  CheckInRange(path, item, "inertia's greatest principal moment", moments[2], kPrincipalInertiaDoc);
  // A rigid body's largest principal moment cannot exceed the sum of the other two.
  if (moments[2] > (moments[0] + moments[1]) * (1.0 + kInertiaTriangleTolerance)) {
    Refuse(path, item,
           "inertia breaks the triangle inequality, principal moments " + listed + " kg m^2");
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

// The three leg joints: present, revolute, with limits the stops fit around, nothing the
// simulator does not model. Also checks that the foot link exists.
std::array<JointDescription, kLegJoints> CheckJoints(const urdf::ModelInterface& model,
                                                     const std::string& path) {
  std::array<JointDescription, kLegJoints> joints;
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
    const double stop_lo = limits.lower - kMechanicalStopMarginRad;
    const double stop_hi = limits.upper + kMechanicalStopMarginRad;
    if (!(limits.lower < limits.upper) || !(stop_lo > -std::numbers::pi) ||
        !(stop_hi < std::numbers::pi)) {
      Refuse(path, "joint '" + name + "'",
             "limit lower and upper [" + Deg(limits.lower) + ", " + Deg(limits.upper) +
                 "] deg must be increasing and leave room for the mechanical stops 3 deg beyond "
                 "them inside (-180, 180) deg");
    }
    if (const std::string problem = KeyValueProblem(limits.effort, kLimitEffortDoc);
        !problem.empty()) {
      Refuse(path, "joint '" + name + "'",
             "limit effort must be " + problem + ", got " + Num(limits.effort));
    }
    joints[j].name = name;
    joints[j].lower_rad = limits.lower;
    joints[j].upper_rad = limits.upper;
    joints[j].effort_nm = limits.effort;
    joints[j].velocity_rad_per_s = limits.velocity;
  }
  if (!model.getLink(std::string(kFootLinkName))) {
    throw std::invalid_argument("link '" + std::string(kFootLinkName) + "' not found in URDF '" +
                                path + "'");
  }
  return joints;
}

// The link tree depth-first, so every parent precedes its children; each link with its joint
// origin and, when it moves, its LegJoint and unit axis.
std::vector<LinkDescription> ReadTree(const urdf::ModelInterface& model, const std::string& path) {
  const urdf::LinkConstSharedPtr root = model.getRoot();
  if (!root) {
    throw std::runtime_error("URDF file '" + path + "' has no root link");
  }
  std::vector<LinkDescription> links;
  std::vector<std::pair<urdf::LinkConstSharedPtr, int>> stack{{root, -1}};
  while (!stack.empty()) {
    const auto [urdf_link, parent] = stack.back();
    stack.pop_back();
    LinkDescription link;
    link.name = urdf_link->name;
    link.parent = parent;
    if (const urdf::JointSharedPtr& joint = urdf_link->parent_joint) {
      CheckOrigin(path, "joint '" + joint->name + "'", "origin",
                  joint->parent_to_joint_origin_transform);
      link.origin = ToRigidTransform(ToIsometry(joint->parent_to_joint_origin_transform));
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
        if (!axis.allFinite() || !(axis.norm() >= 1e-9)) {
          Refuse(path, "joint '" + joint->name + "'",
                 "axis must be finite and non-zero, got (" + Num(axis.x()) + ", " + Num(axis.y()) +
                     ", " + Num(axis.z()) + ")");
        }
        link.joint = index;
        link.axis = ToArray(axis.normalized());
      }
    }
    links.push_back(link);
    const int self = static_cast<int>(links.size()) - 1;
    for (auto it = urdf_link->child_links.rbegin(); it != urdf_link->child_links.rend(); ++it) {
      stack.emplace_back(*it, self);
    }
  }
  return links;
}

// The foot and every joint hang from the root link: urdfdom accepts a cycle of joints beside the
// root (its links then have parents but no path to the root), which the tree walk never reaches.
void CheckReachedFromRoot(const LegDescription& leg, const std::string& path) {
  const std::string where = "' in URDF '" + path + "' does not hang from its root link '" +
                            leg.links.front().name + "' (a cycle of joints?)";
  if (leg.FindLink(kFootLinkName) < 0) {
    throw std::invalid_argument("link '" + std::string(kFootLinkName) + where);
  }
  for (int j = 0; j < kLegJoints; ++j) {
    const bool reached = std::any_of(leg.links.begin(), leg.links.end(),
                                     [j](const LinkDescription& link) { return link.joint == j; });
    if (!reached) throw std::invalid_argument("joint '" + leg.joints[j].name + where);
  }
}

// One body per moving link, each with the masses of the links fixed to it (the root and links
// fixed to it stay put and need no mass). Sets every link's body and in_body.
void LumpBodies(const urdf::ModelInterface& model, LegDescription& leg) {
  std::vector<std::vector<LinkMass>> pieces;
  for (std::size_t i = 1; i < leg.links.size(); ++i) {
    LinkDescription& link = leg.links[i];
    const LinkDescription& parent = leg.links[link.parent];
    if (link.joint >= 0) {
      link.body = static_cast<int>(leg.bodies.size());
      leg.bodies.push_back(BodyDescription{.link = static_cast<int>(i)});
      pieces.emplace_back();
    } else {
      link.body = parent.body;
      link.in_body = ToRigidTransform(ToEigen(parent.in_body) * ToEigen(link.origin));
    }
    const urdf::LinkConstSharedPtr urdf_link = model.getLink(link.name);
    if (link.body >= 0 && urdf_link->inertial) {
      const Eigen::Isometry3d in_body = ToEigen(link.in_body);
      LinkMass mass = CheckedMass(*urdf_link, leg.urdf_path);
      mass.com_m = in_body * mass.com_m;
      mass.inertia_kg_m2 = in_body.linear() * mass.inertia_kg_m2 * in_body.linear().transpose();
      pieces[link.body].push_back(mass);
    }
  }
  for (std::size_t b = 0; b < leg.bodies.size(); ++b) {
    BodyDescription& body = leg.bodies[b];
    const LinkDescription& link = leg.links[body.link];
    if (pieces[b].empty()) {
      throw std::invalid_argument("link '" + link.name + "' (moved by joint '" +
                                  leg.joints[link.joint].name +
                                  "') has no <inertial>: the simulator needs its mass");
    }
    const LinkMass total = Combine(pieces[b]);
    body.mass_kg = total.mass_kg;
    body.com_m = ToArray(total.com_m);
    body.inertia_kg_m2 = ToRowMajor(total.inertia_kg_m2);
  }
}

}  // namespace

int LegDescription::FindLink(std::string_view name) const {
  for (std::size_t i = 0; i < links.size(); ++i) {
    if (links[i].name == name) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

LegDescription LoadLegDescription(const std::string& urdf_path) {
  const urdf::ModelInterfaceSharedPtr model = ParseUrdfFile(urdf_path);
  LegDescription leg;
  leg.urdf_path = urdf_path;
  leg.robot_name = model->getName();
  leg.joints = CheckJoints(*model, urdf_path);
  leg.links = ReadTree(*model, urdf_path);
  CheckReachedFromRoot(leg, urdf_path);
  LumpBodies(*model, leg);

  // The joint frames and the foot at q = 0, in the root frame.
  const std::vector<Eigen::Isometry3d> poses = LinkPoses(leg.links, LegAngles{});
  for (std::size_t i = 1; i < leg.links.size(); ++i) {
    const LinkDescription& link = leg.links[i];
    if (link.joint >= 0) {
      JointDescription& joint = leg.joints[link.joint];
      joint.position_m = ToArray(poses[i].translation());
      joint.axis = ToArray(poses[i].linear() * ToEigen(link.axis));
    }
  }
  leg.foot_position_m = ToArray(poses[leg.FindLink(kFootLinkName)].translation());
  return leg;
}

}  // namespace leglab::sim
