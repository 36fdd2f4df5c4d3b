#include "contact/body_mapping.h"

namespace abd::contact {
namespace {

// q's dof index of coordinate k (x, y, z) times x̃_l: p_k for l = 0, a_{k, l-1} otherwise.
constexpr int dof(int k, int l) { return l == 0 ? k : 3 + 3 * k + (l - 1); }

Eigen::Vector4d homogeneous(const Vec3& x_bar) { return {1.0, x_bar[0], x_bar[1], x_bar[2]}; }

long long block_key(int row, int col) {
  return (static_cast<long long>(row) << 32) | static_cast<unsigned>(col);
}

}  // namespace

void add_stencil_gradient(const ContactMesh& mesh, const std::array<int, 4>& vertices, int nv,
                          const StencilVec& g, double scale, VecX& gradient) {
  for (int u = 0; u < nv; ++u) {
    const int v = vertices[u];
    const Eigen::Vector4d xt = homogeneous(mesh.rest[v]);
    auto qb = gradient.segment<12>(12 * mesh.vertex_body[v]);
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 4; ++l) qb[dof(k, l)] += scale * xt[l] * g[3 * u + k];
  }
}

size_t BodyBlockAccumulator::block_index(int row, int col) {
  const auto [it, inserted] = index_.try_emplace(block_key(row, col), blocks_.size());
  if (inserted) blocks_.push_back({row, col, Mat12::Zero()});
  return it->second;
}

void BodyBlockAccumulator::add_stencil(const ContactMesh& mesh, const std::array<int, 4>& vertices,
                                       int nv, const StencilMat& H, double scale) {
  // The stencil's vertices by body (at most two bodies, local indices 0 and 1).
  std::array<int, 2> body{-1, -1};
  std::array<int, kMaxStencilVertices> local{};
  int n_bodies = 0;
  std::array<Eigen::Vector4d, kMaxStencilVertices> xt;
  for (int u = 0; u < nv; ++u) {
    const int b = mesh.vertex_body[vertices[u]];
    int a = 0;
    while (a < n_bodies && body[a] != b) ++a;
    if (a == n_bodies) body[n_bodies++] = b;
    local[u] = a;
    xt[u] = homogeneous(mesh.rest[vertices[u]]);
  }
  // Block (a, c) = Σ_{u ∈ a, v ∈ c} J_uᵀ H_uv J_v, column by column: S_v = Σ_u J_uᵀ H_uv
  // (12×3), then column dof(m, n) of the block gains x̃_v[n] S_v(:, m). Block (c, a) of a
  // stencil across two bodies is the transpose of (a, c): added as such, not recomputed.
  const std::array<std::array<size_t, 2>, 2> index = [&] {
    std::array<std::array<size_t, 2>, 2> out{};
    for (int a = 0; a < n_bodies; ++a)
      for (int c = 0; c < n_bodies; ++c) out[a][c] = block_index(body[a], body[c]);
    return out;
  }();
  for (int a = 0; a < n_bodies; ++a) {
    for (int c = a; c < n_bodies; ++c) {
      Mat12 B = Mat12::Zero();
      for (int v = 0; v < nv; ++v) {
        if (local[v] != c) continue;
        Eigen::Matrix<double, 12, 3> S = Eigen::Matrix<double, 12, 3>::Zero();
        for (int u = 0; u < nv; ++u) {
          if (local[u] != a) continue;
          const Mat3 Huv = scale * H.block<3, 3>(3 * u, 3 * v);
          for (int l = 0; l < 4; ++l)
            for (int k = 0; k < 3; ++k) S.row(dof(k, l)) += xt[u][l] * Huv.row(k);
        }
        for (int n = 0; n < 4; ++n)
          for (int m = 0; m < 3; ++m) B.col(dof(m, n)) += xt[v][n] * S.col(m);
      }
      blocks_[index[a][c]].H += B;
      if (c != a) blocks_[index[c][a]].H += B.transpose();
    }
  }
}

void BodyBlockAccumulator::flush_into(std::vector<BodyBlock>& out) {
  if (out.empty())
    out.swap(blocks_);  // blocks_ takes out's (empty) storage for the next evaluation
  else
    out.insert(out.end(), blocks_.begin(), blocks_.end());
  clear();
}

}  // namespace abd::contact
