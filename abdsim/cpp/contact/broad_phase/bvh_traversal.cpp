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

namespace {

// The dual-tree descent. An Item holds a pair of node indices (ia, ib); node_a(i) / node_b(i)
// give a node's box when it is pushed, box_a(item) / box_b(item) the boxes of a popped item,
// make(ia, ib, box a, box b) the Item pushed.
template <class Item, class NodeA, class NodeB, class BoxA, class BoxB, class Make>
void descend(const TreeBoxes& a, const TreeBoxes& b, double margin, std::vector<Item>& stack,
             NodeA node_a, NodeB node_b, BoxA box_a, BoxB box_b, Make make,
             const std::function<void(int, int)>& emit) {
  stack.clear();
  auto push = [&](int ia, int ib, const coal::AABB& ba, const coal::AABB& bb) {
    if (boxes_within(ba, bb, margin)) stack.push_back(make(ia, ib, ba, bb));
  };
  push(0, 0, node_a(0), node_b(0));
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const auto& na = a.tree->getBV(unsigned(it.ia));
    const auto& nb = b.tree->getBV(unsigned(it.ib));
    const bool leaf_a = na.isLeaf(), leaf_b = nb.isLeaf();
    if (leaf_a && leaf_b) {
      emit(na.primitiveId(), nb.primitiveId());
    } else if (leaf_b || (!leaf_a && extent(box_a(it)) >= extent(box_b(it)))) {
      push(na.rightChild(), it.ib, node_a(na.rightChild()), box_b(it));
      push(na.leftChild(), it.ib, node_a(na.leftChild()), box_b(it));
    } else {
      push(it.ia, nb.rightChild(), box_a(it), node_b(nb.rightChild()));
      push(it.ia, nb.leftChild(), box_a(it), node_b(nb.leftChild()));
    }
  }
}

}  // namespace

void for_each_close_leaf_pair(const TreeBoxes& a, const TreeBoxes& b, double margin,
                              const std::function<void(int, int)>& emit) {
  // Stacks kept between calls (a query descends hundreds of tree pairs), each looked up once
  // per call; pairs of boxes too far apart are dropped before they are pushed: the same pairs
  // are emitted in the same order.
  if (a.cached && b.cached) {
    // Both trees' node boxes are cached (BroadPhase's small trees: a heap's boxes): the
    // stack holds node indices only and the boxes are read where they are, instead of being
    // copied into every stack entry and out again. The same boxes, tests and order.
    struct Item {
      int ia, ib;
    };
    thread_local std::vector<Item> tls_indices;
    const coal::AABB* const ba = a.cached;
    const coal::AABB* const bb = b.cached;
    descend(
        a, b, margin, tls_indices, [&](int i) -> const coal::AABB& { return ba[i]; },
        [&](int i) -> const coal::AABB& { return bb[i]; },
        [&](const Item& it) -> const coal::AABB& { return ba[it.ia]; },
        [&](const Item& it) -> const coal::AABB& { return bb[it.ib]; },
        [](int ia, int ib, const coal::AABB&, const coal::AABB&) { return Item{ia, ib}; }, emit);
    return;
  }
  struct Item {
    int ia, ib;
    coal::AABB ba, bb;
  };
  thread_local std::vector<Item> tls_boxes;
  descend(
      a, b, margin, tls_boxes, [&](int i) { return a.node(i); }, [&](int i) { return b.node(i); },
      [](const Item& it) -> const coal::AABB& { return it.ba; },
      [](const Item& it) -> const coal::AABB& { return it.bb; },
      [](int ia, int ib, const coal::AABB& ba, const coal::AABB& bb) {
        return Item{ia, ib, ba, bb};
      },
      emit);
}

}  // namespace abd::contact
