#include "contact/active_set.h"

#include <algorithm>
#include <cmath>

namespace abd::contact {

ActiveSet select_active(const ContactMesh& mesh, const ContactTable& table,
                        const Candidates& candidates, VecX q, std::vector<Vec3> x, double reach,
                        double ground_height) {
  ActiveSet set;
  set.q = std::move(q);
  set.x = std::move(x);
  auto consider = [&](const ContactStencil& s) {
    const StencilGeometry g = stencil_geometry(s, set.x, ground_height, 0);
    const double d = s.kind == StencilKind::PointGround
                         ? set.x[s.vertices[0]].z() - ground_height  // signed: below is < 0
                         : std::sqrt(g.d2);
    const double gap = d - s.xi;
    if (!g.infeasible && gap >= reach) return;
    if (g.infeasible && set.infeasible < 0) set.infeasible = int(set.stencils.size());
    set.min_gap = std::min(set.min_gap, gap);
    set.stencils.push_back(s);
    set.distances.push_back({g.d2, g.infeasible});
  };
  auto with_damping = [](ContactStencil s, const ContactRule& r) {
    s.damping = r.damping;
    return s;
  };
  for (const auto& [v, f] : candidates.point_triangle) {
    const ContactRule& r = table.bodies(mesh.vertex_body[v], mesh.face_body[f]);
    consider(with_damping(point_triangle_stencil(mesh, v, f, r.mu), r));
  }
  for (const auto& [a, b] : candidates.edge_edge) {
    const ContactRule& r = table.bodies(mesh.edge_body[a], mesh.edge_body[b]);
    consider(with_damping(edge_edge_stencil(mesh, a, b, r.mu), r));
  }
  for (int v : candidates.point_ground) {
    const ContactRule& r = table.ground(mesh.vertex_body[v]);
    consider(with_damping(point_ground_stencil(mesh, v, r.mu), r));
  }
  return set;
}

}  // namespace abd::contact
