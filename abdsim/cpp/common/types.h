// Fixed-size Eigen types used throughout the core. ABD lives in 12x12 body blocks.
#pragma once
#include <Eigen/Core>
#include <Eigen/Dense>

namespace abd {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Mat3x12 = Eigen::Matrix<double, 3, 12>;
using VecX = Eigen::VectorXd;
// Row-major so that numpy (n, 3) arrays map without a copy.
using MatX3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
using MatX2i = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;
using MatX4i = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;

}  // namespace abd
