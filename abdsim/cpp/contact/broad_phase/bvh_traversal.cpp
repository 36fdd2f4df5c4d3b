#include "contact/broad_phase/bvh_traversal.h"

#include <utility>
#include <vector>

namespace abd::contact {
namespace {

double extent(const coal::AABB& box) { return (box.max_ - box.min_).sum(); }

void add_vertices(coal::AABB& box, const Vec3* x, const coal::Triangle* tri, int prim) {
  if (!tri) {
    box += x[prim];
    return;
  }
  for (int k = 0; k < 3; ++k) box += x[(*tri)[k]];
}

}  // namespace

coal::AABB affine_box(const coal::AABB& rest, const AffineMap& m) {
  const Vec3 c = 0.5 * (rest.min_ + rest.max_), h = 0.5 * (rest.max_ - rest.min_);
  const Vec3 wc = m.A * c + m.p;
  const Vec3 wh = m.A.cwiseAbs() * h + Vec3::Constant(m.pad);
  return coal::AABB(Vec3(wc - wh), Vec3(wc + wh));
}

coal::AABB TreeBoxes::node(int i) const {
  if (cached) return cached[i];
  const auto& n = tree->getBV(unsigned(i));
  if (!affine0) return n.bv;
  if (n.isLeaf()) {
    // Exact: the primitive's vertices (a point cloud's primitive is its vertex).
    const int prim = n.primitiveId();
    const coal::Triangle* tri =
        tree->num_tris > 0 ? &(*tree->tri_indices)[size_t(prim)] : nullptr;
    const Vec3& first = tri ? x0[(*tri)[0]] : x0[prim];
    coal::AABB box(first);
    add_vertices(box, x0, tri, prim);
    if (x1) add_vertices(box, x1, tri, prim);
    return box;
  }
  coal::AABB box = affine_box(n.bv, *affine0);
  if (affine1) box += affine_box(n.bv, *affine1);
  return box;
}

void for_each_close_leaf_pair(const TreeBoxes& a, const TreeBoxes& b, double margin,
                              const std::function<void(int, int)>& emit) {
  struct Item {
    int ia, ib;
    coal::AABB ba, bb;
  };
  // Kept between calls (a query descends hundreds of tree pairs); pairs of boxes too far
  // apart are dropped before they are pushed: the same pairs are emitted in the same order.
  thread_local std::vector<Item> stack;
  stack.clear();
  auto push = [&](int ia, int ib, const coal::AABB& ba, const coal::AABB& bb) {
    if (boxes_within(ba, bb, margin)) stack.push_back({ia, ib, ba, bb});
  };
  push(0, 0, a.node(0), b.node(0));
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const auto& na = a.tree->getBV(unsigned(it.ia));
    const auto& nb = b.tree->getBV(unsigned(it.ib));
    const bool leaf_a = na.isLeaf(), leaf_b = nb.isLeaf();
    if (leaf_a && leaf_b) {
      emit(na.primitiveId(), nb.primitiveId());
    } else if (leaf_b || (!leaf_a && extent(it.ba) >= extent(it.bb))) {
      push(na.rightChild(), it.ib, a.node(na.rightChild()), it.bb);
      push(na.leftChild(), it.ib, a.node(na.leftChild()), it.bb);
    } else {
      push(it.ia, nb.rightChild(), it.ba, b.node(nb.rightChild()));
      push(it.ia, nb.leftChild(), it.ba, b.node(nb.leftChild()));
    }
  }
}

}  // namespace abd::contact
