#include "contact/broad_phase/bvh_traversal.h"

#include <utility>
#include <vector>

namespace abd::contact {
namespace {
double extent(const coal::AABB& box) { return (box.max_ - box.min_).sum(); }
}  // namespace

void for_each_close_leaf_pair(const Bvh& a, const Bvh& b, double margin,
                              const std::function<void(int, int)>& emit) {
  std::vector<std::pair<int, int>> stack{{0, 0}};
  while (!stack.empty()) {
    const auto [ia, ib] = stack.back();
    stack.pop_back();
    const auto& na = a.getBV(unsigned(ia));
    const auto& nb = b.getBV(unsigned(ib));
    if (!boxes_within(na.bv, nb.bv, margin)) continue;
    const bool leaf_a = na.isLeaf(), leaf_b = nb.isLeaf();
    if (leaf_a && leaf_b) {
      emit(na.primitiveId(), nb.primitiveId());
    } else if (leaf_b || (!leaf_a && extent(na.bv) >= extent(nb.bv))) {
      stack.push_back({na.rightChild(), ib});
      stack.push_back({na.leftChild(), ib});
    } else {
      stack.push_back({ia, nb.rightChild()});
      stack.push_back({ia, nb.leftChild()});
    }
  }
}

}  // namespace abd::contact
