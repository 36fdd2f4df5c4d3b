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
  // A stencil touches at most two bodies, so at most four blocks: look each up once, and keep
  // indices (pointers could dangle while blocks_ grows).
  std::array<long long, 4> memo_key{};
  std::array<size_t, 4> memo_index{};
  int n_memo = 0;
  auto index_of = [&](int row, int col) {
    const long long key = block_key(row, col);
    for (int i = 0; i < n_memo; ++i)
      if (memo_key[i] == key) return memo_index[i];
    memo_key[n_memo] = key;
    return memo_index[n_memo++] = block_index(row, col);
  };
  std::array<size_t, kMaxStencilVertices * kMaxStencilVertices> target{};
  for (int u = 0; u < nv; ++u)
    for (int v = 0; v < nv; ++v)
      target[u * nv + v] =
          index_of(mesh.vertex_body[vertices[u]], mesh.vertex_body[vertices[v]]);
  for (int u = 0; u < nv; ++u) {
    const Eigen::Vector4d xu = scale * homogeneous(mesh.rest[vertices[u]]);
    for (int v = 0; v < nv; ++v) {
      const Eigen::Vector4d xv = homogeneous(mesh.rest[vertices[v]]);
      const Mat3 Huv = H.block<3, 3>(3 * u, 3 * v);
      Mat12& B = blocks_[target[u * nv + v]].H;
      for (int l = 0; l < 4; ++l)
        for (int n = 0; n < 4; ++n) {
          const double w = xu[l] * xv[n];
          for (int k = 0; k < 3; ++k)
            for (int m = 0; m < 3; ++m) B(dof(k, l), dof(m, n)) += w * Huv(k, m);
        }
    }
  }
}

void BodyBlockAccumulator::flush_into(std::vector<BodyBlock>& out) {
  out.insert(out.end(), blocks_.begin(), blocks_.end());
  blocks_.clear();
  index_.clear();
}

}  // namespace abd::contact
