#include "contact/broad_phase/body_pairs.h"

#include <algorithm>
#include <stdexcept>

#include <coal/shape/geometric_shapes.h>

namespace abd::contact {
namespace {

struct PairCollector : coal::CollisionCallBackBase {
  std::vector<std::pair<int, int>> pairs;
  bool collide(coal::CollisionObject* o1, coal::CollisionObject* o2) override {
    const int a = *static_cast<const int*>(o1->getUserData());
    const int b = *static_cast<const int*>(o2->getUserData());
    pairs.emplace_back(std::min(a, b), std::max(a, b));
    return false;  // keep going
  }
};

}  // namespace

BodyPairFinder::BodyPairFinder(int n_bodies) : ids_(size_t(n_bodies)) {
  const auto placeholder = std::make_shared<coal::Sphere>(0.0);
  std::vector<coal::CollisionObject*> raw;
  for (int b = 0; b < n_bodies; ++b) {
    ids_[b] = b;
    objects_.push_back(std::make_unique<coal::CollisionObject>(placeholder));
    objects_.back()->setUserData(&ids_[b]);
    raw.push_back(objects_.back().get());
  }
  manager_.registerObjects(raw);
  manager_.setup();
}

std::vector<std::pair<int, int>> BodyPairFinder::overlapping(const std::vector<coal::AABB>& boxes) {
  if (boxes.size() != objects_.size())
    throw std::invalid_argument("BodyPairFinder: one box per body expected");
  for (size_t b = 0; b < boxes.size(); ++b) objects_[b]->getAABB() = boxes[b];
  manager_.update();  // refits the tree to the boxes we just wrote
  PairCollector collector;
  manager_.collide(&collector);
  std::sort(collector.pairs.begin(), collector.pairs.end());
  collector.pairs.erase(std::unique(collector.pairs.begin(), collector.pairs.end()),
                        collector.pairs.end());
  return collector.pairs;
}

}  // namespace abd::contact
