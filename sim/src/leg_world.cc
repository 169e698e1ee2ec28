#include "leglab/sim/leg_world.h"

#include <stdexcept>
#include <string>

#include "physics_world.h"

namespace leglab::sim {
namespace {

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
  LegDescription leg;
  std::unique_ptr<PhysicsWorld> physics;  // refers to `leg`: declared after it
};

LegWorld::LegWorld(const LegDescription& leg, const StandConfig& stand, PhysicsEngine engine)
    : impl_(std::make_unique<Impl>()) {
  CheckStructure(leg);
  impl_->leg = leg;
  impl_->physics = engine == PhysicsEngine::kDart ? MakeDartWorld(impl_->leg, stand)
                                                  : MakeOdeWorld(impl_->leg, stand);
}

LegWorld::LegWorld(const std::string& urdf_path, const StandConfig& stand, PhysicsEngine engine)
    : LegWorld(LoadLegDescription(urdf_path), stand, engine) {}

LegWorld::~LegWorld() = default;
LegWorld::LegWorld(LegWorld&&) noexcept = default;
LegWorld& LegWorld::operator=(LegWorld&&) noexcept = default;

const JointDescription& LegWorld::joint(int joint) const { return impl_->leg.joints.at(joint); }

const LegDescription& LegWorld::description() const { return impl_->leg; }

LegAngles LegWorld::AnglesRad() const { return impl_->physics->AnglesRad(); }

LegAngles LegWorld::RatesRadPerS() const { return impl_->physics->RatesRadPerS(); }

void LegWorld::SetMotor(int joint, double speed_rad_per_s, double max_torque_nm) {
  impl_->physics->SetMotor(joint, speed_rad_per_s, max_torque_nm);
}

void LegWorld::Step(double dt_s) { impl_->physics->Step(dt_s); }

const PlantTelemetry& LegWorld::stand_state() const { return impl_->physics->stand_state(); }

bool LegWorld::has_stand() const { return impl_->physics->has_stand(); }

void LegWorld::SetConfigurationRad(const LegAngles& q_rad) {
  impl_->physics->SetConfigurationRad(q_rad);
}

std::array<double, 3> LegWorld::LinkOriginMm(std::string_view link_name) const {
  const int index = impl_->leg.FindLink(link_name);
  if (index < 0) {
    throw std::invalid_argument("link '" + std::string(link_name) + "' not found in the URDF");
  }
  return impl_->physics->LinkOriginMm(index);
}

double LegWorld::KineticEnergyJ() const { return impl_->physics->KineticEnergyJ(); }

double LegWorld::MechanicalEnergyJ() const { return impl_->physics->MechanicalEnergyJ(); }

std::string LegWorld::StateProblem() const { return impl_->physics->StateProblem(); }

}  // namespace leglab::sim
