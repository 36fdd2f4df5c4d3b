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
// C_b = [H_bP; J_P] its coupling to x_P. With y_b = K_b⁻¹ z_b, P gets
// H_PP −= C_bᵀ K_b⁻¹ C_b and z_P −= C_bᵀ y_b; back-substitution from the roots:
// u_b = y_b − K_b⁻¹ C_b x_P. With H_bb = L Lᵀ and S = J H_bb⁻¹ Jᵀ = L_S L_Sᵀ,
// C_bᵀ K_b⁻¹ C_b = VᵀV − QᵀQ for V = L⁻¹ H_bP and Q = L_S⁻¹ (J H_bb⁻¹ H_bP − J_P): two
// symmetric products, and K_b⁻¹ C_b is only ever applied to a vector.
#pragma once
#include <Eigen/Cholesky>
#include <vector>

#include "solver/block_system.h"
#include "solver/constraint.h"

namespace abd {

class TreeKkt {
 public:
  // A node carries at most 12 rows (more cannot be independent on its 12 unknowns): every
  // per-node matrix has a fixed capacity, so a solve allocates nothing once sized.
  using Rows12 = Eigen::Matrix<double, Eigen::Dynamic, 12, Eigen::RowMajor, 12, 12>;
  using Cols12 = Eigen::Matrix<double, 12, Eigen::Dynamic, Eigen::ColMajor, 12, 12>;
  using Square = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 12, 12>;
  using Values = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 12, 1>;

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
    Rows12 J, JP;                   // m × 12: the node's rows on x_b and on x_P
    Values c;                       // their values
    Eigen::LLT<Square> S;           // J H_bb⁻¹ Jᵀ
    Vec12 yx;                       // y_b = K_b⁻¹ z_b: x part, λ part
    Values yl;
  };
  // Parents of a rooted spanning forest (order_ from the roots down); false when the graph
  // of rows and couplings over free bodies has a cycle.
  bool build_forest(const BlockSystem& system, const std::vector<ConstraintRow>& rows);
  // Node b eliminated into its parent: its factors and y_b; false when a pivot block fails.
  bool factor_node(int b);
  // K_b⁻¹ [rhs; −c] for the node's factors: (x part, λ part).
  void solve_node(const Node& node, const Vec12& rhs, const Values& c, Vec12& x,
                  Values& lambda) const;

  std::vector<Node> nodes_;
  std::vector<int> order_;           // free bodies, every parent before its children
  std::vector<int> row_start_, row_list_;  // CSR: the rows each node carries
  std::vector<std::pair<int, int>> edges_;
  std::vector<int> uf_, adjacency_start_, adjacency_;
  std::vector<unsigned char> unary_;  // per body: carries a row against the world
};

}  // namespace abd
