// The KKT system [H Jᵀ; J −D] [x; λ] = [rhs; −c] of constrained_solve.h when bodies and
// their couplings form a forest (an articulation: every joint, coupling block and soft row
// links a body to its parent, none closes a loop). Hard rows (constraints) have D = 0; the
// soft rows of the system (BlockSystem::soft_rows, a rank-one Hessian k g gᵀ kept out of H)
// have D = 1/k, which is the same system with k g gᵀ added to H. The matrix is then block
// tree-structured with one node per body: its 12 unknowns and the multipliers of the rows
// that tie it to its parent (or to the world). Eliminating nodes leaves first, each into its
// parent, costs a few 12x12 products per body and no fill (the Schur complement of a subtree
// onto its root's x is the Hessian of that subtree minimised under its constraints: SPD when
// H is SPD and each node's hard rows are independent), and it is exact: no regularisation,
// no refinement.
//
// Per node b with parent P: K_b = [H_bb Jᵀ; J −D] (H_bb already updated by b's children),
// C_b = [H_bP; J_P] its coupling to x_P. P gets H_PP −= C_bᵀ K_b⁻¹ C_b and
// z_P −= C_bᵀ K_b⁻¹ z_b; back-substitution from the roots: u_b = K_b⁻¹ (z_b − C_b x_P).
// With H_bb = L Lᵀ, W = J L⁻ᵀ and S = W Wᵀ + D = L_S L_Sᵀ, K_b = F diag(I, −I) Fᵀ for
// F = [L 0; W L_S], so with F⁻¹ C_b = [V; −Q] (V = L⁻¹ H_bP, Q = L_S⁻¹ (W V − J_P)) and
// F⁻¹ z_b = [t; −λ] (t = L⁻¹ r_b, λ = L_S⁻¹ (c + W t)): C_bᵀ K_b⁻¹ C_b = VᵀV − QᵀQ (two
// symmetric products), C_bᵀ K_b⁻¹ z_b = Vᵀ t − Qᵀ λ, and
// u_b = L⁻ᵀ (t − V x_P − Wᵀ L_S⁻ᵀ (λ − Q x_P)): the elimination needs no solve with K_b, the
// back-substitution one per node. A soft row instead of a dense coupling block makes V = 0:
// a rank-one update per row instead of 12x12 products.
//
// Sizes are fixed (12 unknowns, at most 12 rows per node) and the kernels are written for
// them (solver/small_dense.h): a solve allocates nothing once sized. The forest (parents, elimination order,
// which node carries which row) is kept while the rows and couplings join the same bodies.
#pragma once
#include <vector>

#include "solver/block_system.h"
#include "solver/constraint.h"

namespace abd {

class TreeKkt {
 public:
  // Rows carried by one node at most (hard and soft): more hard rows cannot be independent
  // on its 12 unknowns. Soft rows beyond it are folded into the node's coupling block.
  static constexpr int kMaxRows = 12;

  // x over every body (zero on the bodies fixed in `system`), as KktFactorisation::solve.
  // Returns false (x unspecified) when the structure is not a forest, a node carries more
  // hard rows than it can, or a pivot block is not (numerically) positive definite: the
  // caller then takes the general sparse path, which also reports what is wrong.
  bool solve(const BlockSystem& system, const std::vector<ConstraintRow>& rows, const VecX& rhs,
             VecX& x);

 private:
  // Every per-node matrix is 12x12: m < 12 rows are padded with zero rows of compliance 1
  // (their multipliers are 0 and they change nothing), so the kernels run on fixed sizes.
  struct Node {
    int parent = -1;                  // body index, −1 for a root
    const Mat12* coupling = nullptr;  // H_bP (rows b, columns P), null when zero
    Mat12 own_coupling;               // where coupling points when soft rows were folded in
    Mat12 L;                          // H_bb (updated by the children), then its Cholesky
                                      // factor (its diagonal only without a coupling)
    Mat12 Lt;                         // Lᵀ's unit upper factor (dense::cholesky_forward)
    Vec12 r;                          // rhs_b, updated by the children
    Vec12 L_inv_diagonal;             // 1 / diag(L)
    int m = 0;                        // rows 0..hard−1 are hard, hard..m−1 soft
    int hard = 0;
    Mat12 W;                          // the rows J on x_b (row k: row k), then J L⁻ᵀ
    // W's rows and Qt's columns past m, and Lt's and LSt's entries on and below the
    // diagonal are zero: set once per forest (each row k < m refills the same row of W and
    // column of Qt; the factorisations write only above the diagonal of Lt and LSt).
    bool zeroed = false;
    Vec12 c, D;                       // the rows' values and compliances
    Mat12 LS;                         // S = W Wᵀ + D, then its Cholesky factor's diagonal
    Mat12 LSt;                        // L_Sᵀ's unit upper factor
    Vec12 LS_inv_diagonal;
    Vec12 t, lambda;                  // F⁻¹ z_b (K_b = F diag(I, −I) Fᵀ): t = L⁻¹ r_b,
                                      // λ = L_S⁻¹ (c + W t)
    Mat12 V;                          // L⁻¹ H_bP (with a coupling)
    Mat12 Qt;                         // −J_Pᵀ (the rows on x_P, column k: row k), then
                                      // Qᵀ, Q = L_S⁻¹ (W V − J_P)
  };
  // The forest of the rows' and couplings' bodies: parents, order_ (roots first) and which
  // rows each node carries. False when it has a loop or a node carries too many hard rows.
  bool build_forest(const BlockSystem& system, const std::vector<ConstraintRow>& rows);
  // The bodies each row and coupling joins, in order (the forest's key).
  void signature(const BlockSystem& system, const std::vector<ConstraintRow>& rows,
                 std::vector<int>& out) const;
  // The node's blocks, rows and right-hand side from the system (its parent's first).
  bool gather(int b, const BlockSystem& system, const std::vector<ConstraintRow>& rows,
              const VecX& rhs);
  // Node b eliminated into its parent: its factors and y_b; false when a pivot block fails.
  bool factor_node(int b);
  // H_bb's factor with t ← L⁻¹ t, Qᵀ, and the rows' factors with λ ← L_S⁻¹ (c + W t)
  // (R: rows of W computed).
  template <int R>
  static bool factor_rows(Node& node, Vec12& t, Vec12& lambda);

  std::vector<Node> nodes_;
  std::vector<int> order_;                 // free bodies, every parent before its children
  std::vector<int> row_start_, row_list_;  // CSR: the rows each node carries (hard first;
                                           // soft row k is rows.size() + k)
  std::vector<int> key_, key_scratch_;     // signature() of the forest kept
  bool built_ = false;
  std::vector<std::pair<int, int>> edges_;
  std::vector<int> uf_, adjacency_start_, adjacency_, fill_, root_;
  std::vector<unsigned char> unary_;  // per body: carries a row against the world
};

}  // namespace abd
