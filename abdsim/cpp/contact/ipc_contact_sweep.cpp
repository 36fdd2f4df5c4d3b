// IpcContactTerm: broad-phase queries with bounded memory. A Newton direction can move a
// body far (a wild trial moved robot links 0.2 m in one iteration); the swept query of such a
// move through dense meshes finds hundreds of millions of box pairs (std::bad_alloc). The
// move is shortened for the bodies that move farthest until the query fits: a shorter move
// still gives conservative step bounds (the solver never steps past a body's checked part).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "contact/ccd/additive_ccd.h"
#include "contact/ground/ground_plane.h"
#include "contact/ipc_contact_term.h"
#include "contact/parallel.h"
#include "solver/diagnostics.h"

namespace abd {
using namespace contact;

namespace {

// Shortening rounds: each cuts the largest move by 4 (4^-16 ≈ 2e-10 of it).
constexpr int kMaxShortenings = 16;

// Time of impact of a stencil whose vertices move linearly from p0 to p1.
double stencil_toi(const ContactStencil& s, const std::array<Vec3, 4>& p0,
                   const std::array<Vec3, 4>& p1, double ground_height, CcdOptions o) {
  o.min_distance = s.xi;
  switch (s.kind) {
    case StencilKind::PointTriangle:
      return point_triangle_ccd(p0[0], p0[1], p0[2], p0[3], p1[0], p1[1], p1[2], p1[3], o);
    case StencilKind::EdgeEdge:
      return edge_edge_ccd(p0[0], p0[1], p0[2], p0[3], p1[0], p1[1], p1[2], p1[3], o);
    default: return point_ground_ccd(p0[0], p1[0], ground_height, o);
  }
}

std::string overflow_message(const Candidates& c, size_t cap, const char* what) {
  std::ostringstream os;
  os << "contact broad phase: " << what << " found more than " << cap
     << " candidate pairs (bodies " << c.overflow_bodies[0] << " and ";
  if (c.overflow_bodies[1] < 0)
    os << "the ground";
  else
    os << c.overflow_bodies[1];
  os << "); set_max_candidates raises the limit";
  return os.str();
}

}  // namespace

void IpcContactTerm::set_max_candidates(size_t n) {
  if (n == 0) throw std::invalid_argument("set_max_candidates: the limit must be > 0");
  max_candidates_ = n;
  swept_.valid = false;
}

Candidates IpcContactTerm::bounded_query(const std::vector<Vec3>& x,
                                         const BroadPhaseQuery& query) const {
  BroadPhaseQuery q = query;
  q.max_candidates = max_candidates_;
  Candidates c = timed(broad_phase_seconds_, [&] { return verlet_.query(broad_phase_, mesh_, x, nullptr, q); });
  if (c.overflow) throw SolverError(overflow_message(c, max_candidates_, "a query"));
  return c;
}

IpcContactTerm::Sweep IpcContactTerm::bounded_sweep(const VecX& q, const VecX& dq,
                                                    double margin) const {
  const int nb = mesh_.num_bodies();
  const std::vector<Vec3>* start = &vertices_at(q, sweep_start_);
  if (start == &sweep_end_) {  // this move starts where the last one ended: keep its vertices
    sweep_start_.swap(sweep_end_);
    start = &sweep_start_;
  }
  const std::vector<Vec3>& x0 = *start;
  std::vector<Vec3>& x_end = sweep_end_;
  sweep_end_q_ = q + dq;
  mesh_.world_vertices_into(sweep_end_q_, x_end);
  // The largest vertex move of each body (vertices are linear in q: a shortened move
  // q_b + s dq_b takes each vertex to x0 + s (x_end − x0)); only needed, and computed, once a
  // query overflows.
  std::vector<double> reach;
  auto largest_moves = [&] {
    reach.assign(size_t(nb), 0.0);
    for (int b = 0; b < nb; ++b)
      for (int v = mesh_.vertex_offset[b]; v < mesh_.vertex_offset[b + 1]; ++v)
        reach[size_t(b)] = std::max(reach[size_t(b)], (x_end[v] - x0[v]).norm());
  };

  BroadPhaseQuery query;
  query.margin = margin;
  query.ground = settings_.ground;
  query.ground_height = settings_.ground_height;
  query.max_candidates = max_candidates_;
  Sweep out;
  out.x0 = &x0;
  out.scale.assign(size_t(nb), 1.0);
  std::vector<Vec3> shortened;  // x1 once a body's move is cut (until then: x_end)
  for (int round = 0;; ++round) {
    const std::vector<Vec3>& x1 = shortened.empty() ? x_end : shortened;
    out.candidates = timed(broad_phase_seconds_,
                           [&] { return verlet_.query(broad_phase_, mesh_, x0, &x1, query); });
    if (!out.candidates.overflow) break;
    if (reach.empty()) {
      largest_moves();
      shortened = x_end;
    }
    double longest = 0.0;
    for (int b = 0; b < nb; ++b) longest = std::max(longest, out.scale[size_t(b)] * reach[size_t(b)]);
    if (round == kMaxShortenings || longest == 0.0)
      throw SolverError(overflow_message(out.candidates, max_candidates_, "a swept query"));
    // Every body that moves farther than a quarter of the longest move is cut to it.
    const double limit = 0.25 * longest;
    for (int b = 0; b < nb; ++b) {
      double& s = out.scale[size_t(b)];
      if (s * reach[size_t(b)] <= limit) continue;
      s = limit / reach[size_t(b)];
      for (int v = mesh_.vertex_offset[b]; v < mesh_.vertex_offset[b + 1]; ++v)
        shortened[v] = x0[v] + s * (x_end[v] - x0[v]);
    }
  }

  const Candidates& c = out.candidates;
  std::vector<ContactStencil>& stencils = out.stencils;
  stencils.reserve(c.point_triangle.size() + c.edge_edge.size() + c.point_ground.size());
  for (const auto& [v, f] : c.point_triangle) stencils.push_back(point_triangle_stencil(mesh_, v, f, 0.0));
  for (const auto& [a, b] : c.edge_edge) stencils.push_back(edge_edge_stencil(mesh_, a, b, 0.0));
  for (int v : c.point_ground) stencils.push_back(point_ground_stencil(mesh_, v, 0.0));

  CcdOptions options;
  options.target = settings_.ccd_target;
  const int n = int(stencils.size());
  out.toi.assign(size_t(n), 1.0);
  // The barrier's sweep (margin > 0) also keeps each pair's gap bound along the path, each
  // side along its own body's checked move (the line search may stop bodies apart).
  const bool keep_reach = margin > 0.0;
  if (keep_reach) out.reach.resize(size_t(n));
  for_each_stencil(n, n >= kMinParallelCcd, threads_, [&](int i) {
    const ContactStencil& s = stencils[size_t(i)];
    // Both bodies of a pair move together (one island, one step length): along the shorter
    // of their two checked moves.
    double m = out.scale[size_t(s.bodies[0])];
    if (s.bodies[1] >= 0) m = std::min(m, out.scale[size_t(s.bodies[1])]);
    std::array<Vec3, 4> p0, p1;
    bool moving = false;  // pairs that do not move keep their distance: no CCD needed
    for (int k = 0; k < s.nv; ++k) {
      const int v = s.vertices[size_t(k)];
      p0[size_t(k)] = x0[v];
      p1[size_t(k)] = m == 1.0 ? x_end[v] : Vec3(x0[v] + m * (x_end[v] - x0[v]));
      moving = moving || p0[size_t(k)] != p1[size_t(k)];
    }
    double gap0 = std::numeric_limits<double>::quiet_NaN();  // CCD's d − ξ at the start
    CcdOptions::Moves moves;  // and its bound on the sides' moves
    CcdOptions o = options;
    if (keep_reach) {
      o.start_gap = &gap0;
      o.moves = &moves;
    }
    out.toi[size_t(i)] = m * (moving ? stencil_toi(s, p0, p1, settings_.ground_height, o) : 1.0);
    if (keep_reach && s.kind != StencilKind::PointGround && !std::isnan(gap0) &&
        (s.bodies[1] < 0 || out.scale[size_t(s.bodies[0])] == out.scale[size_t(s.bodies[1])])) {
      // Both sides along one checked move, the CCD's: its gap and moves are the bound's.
      out.reach[size_t(i)] =
          path_reach_from_ccd(s, x0, gap0, moves.first, moves.second, moves.common);
    } else if (keep_reach) {
      for (int k = 0; k < s.nv; ++k) {
        const int v = s.vertices[size_t(k)];
        const double sb = out.scale[size_t(mesh_.vertex_body[v])];
        p1[size_t(k)] = sb == 1.0 ? x_end[v] : Vec3(x0[v] + sb * (x_end[v] - x0[v]));
      }
      out.reach[size_t(i)] = path_reach(s, x0, p1, settings_.ground_height, gap0);
    }
  });
  return out;
}

// One swept query for the whole line, then only the pairs it did not clear are restarted,
// each from where its own CCD stopped: the query's candidates cover any part of the line, and
// a pair cleared to the end stays clear on every part of it. (Restarting every pair from the
// earliest stop, with a query each time, cost 16 queries for a line that crosses: 40 ms in
// the 100-box heap, against 4 ms for one that does not.)
//
// A restart from a gap at or below `touching` is contact, whatever its CCD answers: from a gap
// at round-off its distances are noise. In a landing 20-box heap an edge's CCD closed its gap
// tenfold per restart down to 2.6e-17 m, then found no impact and advanced 0.70 of the rest
// of the line, through the face it was closing on (test_heap_newton.py); the rest was clear.
bool IpcContactTerm::line_crosses(const VecX& q, const VecX& dq, int restarts,
                                  double touching) const {
  if (restarts < 1)
    throw std::invalid_argument("line_crosses: restarts must be >= 1, got " +
                                std::to_string(restarts));
  if (!(touching >= 0.0) || !std::isfinite(touching))
    throw std::invalid_argument("line_crosses: the touching gap must be finite and >= 0");
  const Sweep sweep = bounded_sweep(q, dq, 0.0);
  const bool shortened = std::any_of(sweep.scale.begin(), sweep.scale.end(),
                                     [](double s) { return s < 1.0; });
  if (shortened) {  // the query did not cover the line: restart all of it (max_step)
    double t = 0.0;
    for (int k = 0; k < restarts; ++k) {
      if (k > 0 && min_distance(q + t * dq, touching) <= touching) return true;
      const double alpha = max_step(q + t * dq, (1.0 - t) * dq);
      if (alpha >= 1.0) return false;
      t += (1.0 - t) * alpha;
    }
    return true;
  }
  std::vector<int> open;
  for (int i = 0; i < int(sweep.toi.size()); ++i)
    if (sweep.toi[size_t(i)] < 1.0) open.push_back(i);
  if (open.empty()) return false;
  const std::vector<Vec3>& x0 = *sweep.x0;
  const std::vector<Vec3>& x1 = sweep_end_;  // bounded_sweep left q + dq's vertices there
  CcdOptions options;
  options.target = settings_.ccd_target;
  std::vector<unsigned char> crosses(open.size(), 0);
  for_each_stencil(int(open.size()), int(open.size()) >= kMinParallelCcd, threads_, [&](int j) {
    const ContactStencil& s = sweep.stencils[size_t(open[size_t(j)])];
    double t = sweep.toi[size_t(open[size_t(j)])];
    std::array<Vec3, 4> p0, p1;
    for (int k = 0; k < s.nv; ++k) p1[size_t(k)] = x1[s.vertices[size_t(k)]];
    for (int k = 1; k < restarts; ++k) {
      for (int v = 0; v < s.nv; ++v) {
        const int i = s.vertices[size_t(v)];
        p0[size_t(v)] = x0[i] + t * (x1[i] - x0[i]);
      }
      // The gap d − ξ where this restart starts: the CCD's, or the height above the ground
      // (whose CCD is exact and reports none); NaN for a pair that does not move (clear).
      double gap = s.kind == StencilKind::PointGround
                       ? p0[0].z() - settings_.ground_height - s.xi
                       : std::numeric_limits<double>::quiet_NaN();
      CcdOptions o = options;
      o.start_gap = &gap;
      const double alpha = stencil_toi(s, p0, p1, settings_.ground_height, o);
      if (gap <= touching) {  // contact at round-off, whatever the CCD answers from there
        crosses[size_t(j)] = 1;
        return;
      }
      if (alpha >= 1.0) return;
      t += (1.0 - t) * alpha;
    }
    crosses[size_t(j)] = 1;
  });
  return std::find(crosses.begin(), crosses.end(), 1) != crosses.end();
}

}  // namespace abd
