// Small fixed-capacity Eigen types for contact stencils. A stencil has at most 4 vertices
// (point–triangle, edge–edge); the ground stencil has 1. "Dynamic with a maximum" keeps
// everything on the stack while letting one code path serve every stencil size.
#pragma once
#include <array>

#include "common/types.h"

namespace abd::contact {

constexpr int kMaxStencilVertices = 4;
constexpr int kMaxStencilDofs = 3 * kMaxStencilVertices;

using StencilVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxStencilDofs, 1>;
using StencilMat =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxStencilDofs, kMaxStencilDofs>;
using StencilWeights = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxStencilVertices, 1>;

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Mat3x2 = Eigen::Matrix<double, 3, 2>;

}  // namespace abd::contact
