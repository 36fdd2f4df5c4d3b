// The KKT system [H Jᵀ; J 0] [x; λ] = [rhs; −c] of constrained_solve.h when bodies and
// their couplings form a forest (an articulation: every joint and every coupling block links
// a body to its parent, none closes a loop). Then the matrix is block tree-structured with
// one node per body: its 12 unknowns and the multipliers of the rows that tie it to its
// parent (or to the world). Eliminating nodes leaves first, each into its parent, costs a
// few 12x12 products per body and no fill (the Schur complement of a subtree onto its root's
// x is the Hessian of that subtree minimised under its constraints: SPD when H is SPD and
// each node's own rows are independent), and it is exact: no regularisation, no refinement.
//
// Per node b with parent P: K_b = [H_bb Jᵀ; J 0] (H_bb already updated by b's children),
// C_b = [H_bP; J_P] its coupling to x_P. With y_b = K_b⁻¹ z_b and W_b = K_b⁻¹ C_b, P gets
// H_PP −= C_bᵀ W_b and z_P −= C_bᵀ y_b; back-substitution from the roots: u_b = y_b − W_b x_P.
// K_b⁻¹ goes through the Cholesky factors of H_bb and of S = J H_bb⁻¹ Jᵀ (range space).
#pragma once
#include <Eigen/Cholesky>
#include <vector>

#include "solver/block_system.h"
#include "solver/constraint.h"

namespace abd {

class TreeKkt {
 public:
  // x over every body (zero on the bodies fixed in `system`), as KktFactorisation::solve.
  // Returns false (x unspecified) when the structure is not a forest, a node carries more
  // rows than it has unknowns, or a pivot block is not (numerically) positive definite: the
  // caller then takes the general sparse path, which also reports what is wrong.
  bool solve(const BlockSystem& system, const std::vector<ConstraintRow>& rows, const VecX& rhs,
             VecX& x);

 private:
  struct Node {
    int parent = -1;                // body index, −1 for a root
    const Mat12* coupling = nullptr;  // H_bP (rows b, columns P), null when zero
    Mat12 H;                        // H_bb, then updated by the children
    Vec12 r;                        // rhs_b, updated by the children
    Eigen::LLT<Mat12> llt;
    Eigen::MatrixXd J, JP;          // m × 12: the node's rows on x_b and on x_P
    Eigen::VectorXd c;              // their values
    Eigen::MatrixXd HiJt;           // H_bb⁻¹ Jᵀ (12 × m)
    Eigen::LLT<Eigen::MatrixXd> S;  // J H_bb⁻¹ Jᵀ
    Vec12 yx;                       // y_b = K_b⁻¹ z_b: x part, λ part
    Eigen::VectorXd yl;
    Mat12 Wx;                       // W_b = K_b⁻¹ C_b: x part, λ part
    Eigen::MatrixXd Wl;
  };
  // Parents of a rooted spanning forest (order_ from the roots down); false when the graph
  // of rows and couplings over free bodies has a cycle.
  bool build_forest(const BlockSystem& system, const std::vector<ConstraintRow>& rows);
  // Node b eliminated: its factors, y_b and W_b; false when a pivot block fails.
  bool factor_node(int b);

  std::vector<Node> nodes_;
  std::vector<int> order_;           // free bodies, every parent before its children
  std::vector<int> row_start_, row_list_;  // CSR: the rows each node carries
  std::vector<std::pair<int, int>> edges_;
  std::vector<int> uf_, adjacency_start_, adjacency_;
  std::vector<unsigned char> unary_;  // per body: carries a row against the world
};

}  // namespace abd
