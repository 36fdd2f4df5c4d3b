// IpcContactTerm: the contact forces it applies, per pair and per body (read-only; the
// energies themselves are in ipc_contact_term.cpp). Vertex forces are −∇_x of each stencil's
// barrier and friction potential; a side's force is the sum over its vertices, its torque the
// sum of (x − centre) × f, so per-pair and per-body results add up to the same totals.
#include <map>
#include <stdexcept>
#include <string>

#include "contact/ipc_contact_term.h"

namespace abd {
using namespace contact;

namespace {

// Stencils are identified by their vertex list: friction stencils are lagged copies of the
// barrier stencils of the step's start.
using StencilKey = std::array<int, 5>;
StencilKey key_of(int nv, const std::array<int, 4>& v) { return {nv, v[0], v[1], v[2], v[3]}; }

// Closest points of a stencil from its weights (r = Σ w_i x_i, positive on the first side),
// the normal from the second side to the first, and the record's point between them.
void set_point_and_normal(const std::array<int, 4>& vertices, int nv, const StencilWeights& w,
                          const std::vector<Vec3>& x, double ground_height, ContactForce& out) {
  Vec3 first = Vec3::Zero(), second = Vec3::Zero();
  if (nv == 1) {  // a vertex and the ground plane z = h
    first = x[vertices[0]];
    second = Vec3(first.x(), first.y(), ground_height);
    out.normal = Vec3::UnitZ();
  } else {
    for (int i = 0; i < nv; ++i) {
      if (w[i] > 0.0) first += w[i] * x[vertices[i]];
      if (w[i] < 0.0) second -= w[i] * x[vertices[i]];
    }
    const Vec3 r = first - second;
    const double length = r.norm();
    // A feasible pair has a positive distance; a zero r only for a degenerate lagged pair.
    out.normal = length > 0.0 ? Vec3(r / length) : Vec3::Zero();
  }
  out.point = 0.5 * (first + second);
}

// −Σ of the vertex gradients over the first side: the first `count` vertices.
Vec3 first_side_force(const StencilVec& grad, int count) {
  Vec3 f = Vec3::Zero();
  for (int i = 0; i < count; ++i) f -= grad.segment<3>(3 * i);
  return f;
}

// A barrier stencil's first side: the point, or the first edge. (Its mollifier moves the
// vertices of a side that the closest points do not weigh, so weights cannot tell.)
int first_side_count(StencilKind kind) { return kind == StencilKind::EdgeEdge ? 2 : 1; }

// A friction stencil's force on vertex i is proportional to its lagged weight w_i, positive on
// the first side: that side's force sums the vertices of positive weight.
Vec3 friction_first_side_force(const StencilVec& grad, const StencilWeights& w, int nv) {
  Vec3 f = Vec3::Zero();
  for (int i = 0; i < nv; ++i)
    if (w[i] > 0.0) f -= grad.segment<3>(3 * i);
  return f;
}

}  // namespace

std::vector<ContactForce> IpcContactTerm::contact_forces(const VecX& q) const {
  if (q.size() != 12 * Eigen::Index(mesh_.num_bodies()))
    throw std::invalid_argument("contact_forces: q must hold 12 values per body");
  ActiveSet scratch;
  const ActiveSet& set = active_set_at(q, scratch);
  if (set.infeasible >= 0)
    throw std::invalid_argument("contact_forces: q is infeasible (a pair within its thickness)");
  const BarrierParams p = barrier_params(kappa_);
  std::vector<ContactForce> out;
  std::map<StencilKey, size_t> index;
  for (const ContactStencil& s : set.stencils) {
    const StencilEnergy e = stencil_barrier(s, set.x, p, 1);
    const StencilGeometry g = stencil_geometry(s, set.x, settings_.ground_height, 0);
    ContactForce c;
    c.bodies = s.bodies;
    set_point_and_normal(s.vertices, s.nv, g.w, set.x, settings_.ground_height, c);
    c.normal_force = first_side_force(e.grad, first_side_count(s.kind)).dot(c.normal);
    c.energy = e.value;
    index.emplace(key_of(s.nv, s.vertices), out.size());
    out.push_back(c);
  }
  for (const FrictionStencil& f : friction_) {
    const StencilEnergy e = friction_energy(f, set.x, friction_eps_, 1);
    const Vec3 force = friction_first_side_force(e.grad, f.w, f.nv);
    const auto it = index.find(key_of(f.nv, f.vertices));
    if (it != index.end()) {
      out[it->second].friction += force;
      continue;
    }
    // Lagged at the step's start, out of the barrier's reach now: friction only.
    ContactForce c;
    c.bodies = stencil_bodies(f.vertices, f.nv);
    set_point_and_normal(f.vertices, f.nv, f.w, set.x, settings_.ground_height, c);
    c.friction = force;
    index.emplace(key_of(f.nv, f.vertices), out.size());
    out.push_back(c);
  }
  // The normal dampers' forces act along the lagged normal, with the barrier's.
  for (const DampingStencil& d : damping_) {
    const StencilEnergy e = damping_energy(d, set.x, step_scale(), 1);
    const Vec3 force = friction_first_side_force(e.grad, d.w, d.nv);
    const auto it = index.find(key_of(d.nv, d.vertices));
    if (it != index.end()) {
      ContactForce& c = out[it->second];
      c.normal_force += force.dot(c.normal);
      c.friction += force - force.dot(c.normal) * c.normal;  // the lagged normal's tilt
      continue;
    }
    ContactForce c;
    c.bodies = stencil_bodies(d.vertices, d.nv);
    set_point_and_normal(d.vertices, d.nv, d.w, set.x, settings_.ground_height, c);
    c.normal_force = force.dot(c.normal);
    c.friction = force - c.normal_force * c.normal;
    out.push_back(c);
  }
  std::vector<ContactForce> nonzero;
  nonzero.reserve(out.size());
  for (const ContactForce& c : out)
    if (c.normal_force != 0.0 || !c.friction.isZero(0.0)) nonzero.push_back(c);
  return nonzero;
}

WrenchMatrix IpcContactTerm::contact_wrenches(const VecX& q,
                                              const std::vector<Vec3>& centers) const {
  const int n = mesh_.num_bodies();
  if (q.size() != 12 * Eigen::Index(n))
    throw std::invalid_argument("contact_wrenches: q must hold 12 values per body");
  if (int(centers.size()) != n)
    throw std::invalid_argument("contact_wrenches: centers must hold one point per body (" +
                                std::to_string(n) + ")");
  ActiveSet scratch;
  const ActiveSet& set = active_set_at(q, scratch);
  if (set.infeasible >= 0)
    throw std::invalid_argument("contact_wrenches: q is infeasible (a pair within its thickness)");
  WrenchMatrix W = WrenchMatrix::Zero(n, 6);
  auto add = [&](const std::array<int, 4>& vertices, int nv, const StencilVec& grad) {
    for (int i = 0; i < nv; ++i) {
      const int v = vertices[i];
      const int b = mesh_.vertex_body[v];
      const Vec3 f = -grad.segment<3>(3 * i);
      W.block<1, 3>(b, 0) += f.transpose();
      W.block<1, 3>(b, 3) += (set.x[v] - centers[b]).cross(f).transpose();
    }
  };
  const BarrierParams p = barrier_params(kappa_);
  for (const ContactStencil& s : set.stencils)
    add(s.vertices, s.nv, stencil_barrier(s, set.x, p, 1).grad);
  for (const FrictionStencil& f : friction_)
    add(f.vertices, f.nv, friction_energy(f, set.x, friction_eps_, 1).grad);
  for (const DampingStencil& d : damping_)
    add(d.vertices, d.nv, damping_energy(d, set.x, step_scale(), 1).grad);
  return W;
}

}  // namespace abd
