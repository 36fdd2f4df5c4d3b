// Builds a joint's rest-space frame from the bodies' states at load, checking the joint
// (std::invalid_argument naming it).
#pragma once
#include "joints/joint_spec.h"
#include "solver/scene_data.h"

namespace abd {

JointFrame make_joint_frame(const JointSpec& spec, const SceneData& scene, const VecX& q0);

}  // namespace abd
