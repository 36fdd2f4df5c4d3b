#include "contact/broad_phase/body_bvh.h"

#include <stdexcept>
#include <type_traits>

namespace abd::contact {

// coal's vectors are Eigen double 3-vectors: our positions pass to coal without conversion.
static_assert(std::is_same_v<coal::Vec3s, Vec3>, "coal must be built with double precision");

namespace {

std::unique_ptr<Bvh> build(const std::vector<Vec3>& points, const std::vector<coal::Triangle>& tris) {
  auto bvh = std::make_unique<Bvh>();
  bvh->beginModel(static_cast<unsigned>(tris.size()), static_cast<unsigned>(points.size()));
  if (tris.empty())
    bvh->addSubModel(points);
  else
    bvh->addSubModel(points, tris);
  bvh->endModel();
  return bvh;
}

}  // namespace

BodyBvh::BodyBvh(const std::vector<Vec3>& rest, const std::vector<std::array<int, 2>>& edges,
                 const std::vector<std::array<int, 3>>& faces) {
  if (rest.empty()) throw std::invalid_argument("a contact body needs at least one vertex");
  vertices_ = build(rest, {});
  if (!edges.empty()) {
    std::vector<coal::Triangle> tris;
    for (const auto& e : edges) tris.emplace_back(e[0], e[1], e[1]);
    edges_ = build(rest, tris);
  }
  if (!faces.empty()) {
    std::vector<coal::Triangle> tris;
    for (const auto& f : faces) tris.emplace_back(f[0], f[1], f[2]);
    faces_ = build(rest, tris);
  }
}

void BodyBvh::update_all(const std::vector<Vec3>& x) {
  at_rest_ = false;
  for (Bvh* t : {vertices_.get(), edges_.get(), faces_.get()}) {
    if (!t) continue;
    t->beginUpdateModel();  // the current frame becomes the previous one
    t->updateSubModel(x);
    t->endUpdateModel(true, true);
  }
}

void BodyBvh::refit(const std::vector<Vec3>& x) {
  update_all(x);
  update_all(x);
}

void BodyBvh::refit_swept(const std::vector<Vec3>& x0, const std::vector<Vec3>& x1) {
  update_all(x0);
  update_all(x1);
}

}  // namespace abd::contact
