// From vertex space to ABD body space. A vertex of body b moves as x = J(x̄) q_b, so a
// stencil's vertex-space gradient g and Hessian H map to bodies as Σ_u J_uᵀ g_u and
// Σ_{u,v} J_uᵀ H_uv J_v, summed into the 12×12 block (body(u), body(v)). A stencil spans at
// most two bodies, giving blocks (i,i), (i,j), (j,i), (j,j).
//
// J(x̄) has the structure x_k = p_k + Σ_l x̄_l a_{k,l}, so with x̃ = [1, x̄] the product
// J_uᵀ H J_v is x̃_u x̃_vᵀ ⊗ H (in q's dof order), computed directly instead of through
// dense 3×12 matrices.
#pragma once
#include <array>
#include <unordered_map>
#include <vector>

#include "contact/contact_mesh.h"
#include "contact/stencil_types.h"
#include "solver/energy_term.h"

namespace abd::contact {

// gradient (12 · n_bodies) += scale · Σ_u J_uᵀ g_u
void add_stencil_gradient(const ContactMesh& mesh, const std::array<int, 4>& vertices, int nv,
                          const StencilVec& g, double scale, VecX& gradient);

// Sums stencil Hessians into one block per (row body, column body), in the order the blocks
// are first touched: the same stencils in the same order give bit-identical output. Kept
// from one evaluation to the next, it keeps its storage (a heap of 100 boxes assembles ~600
// blocks of 1.2 kB per Newton iteration).
class BodyBlockAccumulator {
 public:
  void add_stencil(const ContactMesh& mesh, const std::array<int, 4>& vertices, int nv,
                   const StencilMat& H, double scale);
  // Appends the accumulated blocks to `out` (swapped in when `out` is empty: no copy) and
  // clears the accumulator.
  void flush_into(std::vector<BodyBlock>& out);
  // Drops what was added (keeping the storage).
  void clear() {
    blocks_.clear();
    index_.clear();
  }

 private:
  size_t block_index(int row, int col);
  std::unordered_map<long long, size_t> index_;
  std::vector<BodyBlock> blocks_;
};

}  // namespace abd::contact
