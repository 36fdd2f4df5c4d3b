#include "joints/joint_rows.h"

#include "common/affine.h"
#include "joints/joint_state.h"

namespace abd {
namespace {

// The rows' values, shared by the rows and the values-only check (the same numbers).
Vec3 point_gap(const Vec12& qc, const Vec12& qp, const Vec3& xc_bar, const Vec3& xp_bar) {
  return affine_point(qc, xc_bar) - affine_point(qp, xp_bar);
}
Mat3 frame_gap(const JointFrame& f, const Vec12& qc, const Vec12& qp) {
  return affine_A(qc) * f.basis_c - affine_A(qp) * f.basis_p;
}
double offset_value(const Vec3& n, const Vec3& d) { return n.dot(d); }

// (x_c − x_p)_k for the rest points xc̄ (child) and xp̄ (parent), k = 0..2.
void point_rows(const JointFrame& f, const Vec12& qc, const Vec12& qp, const Vec3& xc_bar,
                const Vec3& xp_bar, std::vector<ConstraintRow>& rows) {
  const Vec3 gap = point_gap(qc, qp, xc_bar, xp_bar);
  for (int k = 0; k < 3; ++k) {
    ConstraintRow& r = rows.emplace_back();  // built in place: no copy of the row
    r.body_a = f.spec.child;
    r.body_b = f.spec.parent;
    r.ja[k] = 1.0;
    r.ja.segment<3>(3 + 3 * k) = xc_bar;
    r.jb[k] = -1.0;
    r.jb.segment<3>(3 + 3 * k) = -xp_bar;
    r.value = gap[k];
  }
}

// (A_c ē_c − A_p ē_p)_k for the three world directions of the load frame.
void frame_rows(const JointFrame& f, const Vec12& qc, const Vec12& qp,
                std::vector<ConstraintRow>& rows) {
  const Mat3 gap = frame_gap(f, qc, qp);
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k) {
      ConstraintRow& r = rows.emplace_back();
      r.body_a = f.spec.child;
      r.body_b = f.spec.parent;
      r.ja.segment<3>(3 + 3 * k) = f.basis_c.col(j);
      r.jb.segment<3>(3 + 3 * k) = -f.basis_p.col(j);
      r.value = gap(k, j);
    }
}

// n·(x_c − x_p) with n = A_p n̄ for the two normals of the parent's axis.
void offset_rows(const JointFrame& f, const Vec12& qc, const Vec12& qp,
                 std::vector<ConstraintRow>& rows) {
  const Vec3 d = affine_point(qc, f.anchor_c) - affine_point(qp, f.anchor_p);
  const Mat3 Ap = affine_A(qp);
  for (const Vec3& n_bar : {f.normal_p, f.normal2_p}) {
    const Vec3 n = Ap * n_bar;
    ConstraintRow& r = rows.emplace_back();
    r.body_a = f.spec.child;
    r.body_b = f.spec.parent;
    for (int k = 0; k < 3; ++k) {
      r.ja[k] = n[k];
      r.ja.segment<3>(3 + 3 * k) = n[k] * f.anchor_c;
      r.jb[k] = -n[k];
      // ∂/∂a_k of n·d: −n_k x̄_p from d, d_k n̄ from n_k = a_k·n̄.
      r.jb.segment<3>(3 + 3 * k) = -n[k] * f.anchor_p + d[k] * n_bar;
    }
    r.value = offset_value(n, d);
  }
}

}  // namespace

namespace {

// add(value) for every row of the joint, in the order of append_joint_rows.
template <class Add>
void for_each_value(const JointFrame& f, const VecX& q, Add&& add) {
  const Vec12 qc = body_q(q, f.spec.child);
  const Vec12 qp = body_q(q, f.spec.parent);
  auto add_point = [&](const Vec3& xc_bar, const Vec3& xp_bar) {
    const Vec3 gap = point_gap(qc, qp, xc_bar, xp_bar);
    for (int k = 0; k < 3; ++k) add(gap[k]);
  };
  auto add_frame = [&]() {
    const Mat3 gap = frame_gap(f, qc, qp);
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) add(gap(k, j));
  };
  switch (f.spec.kind) {
    case JointKind::kFree:
      break;
    case JointKind::kBall:
      add_point(f.anchor_c, f.anchor_p);
      break;
    case JointKind::kRevolute:
      add_point(f.anchor_c, f.anchor_p);
      add_point(f.tip_c, f.tip_p);
      break;
    case JointKind::kFixed:
      add_point(f.anchor_c, f.anchor_p);
      add_frame();
      break;
    case JointKind::kPrismatic: {
      add_frame();
      const Vec3 d = affine_point(qc, f.anchor_c) - affine_point(qp, f.anchor_p);
      const Mat3 Ap = affine_A(qp);
      for (const Vec3& n_bar : {f.normal_p, f.normal2_p}) add(offset_value(Ap * n_bar, d));
      break;
    }
  }
}

}  // namespace

void append_joint_values(const JointFrame& f, const VecX& q, std::vector<ConstraintValue>& out) {
  for_each_value(f, q, [&](double v) { out.push_back({f.spec.child, f.spec.parent, v}); });
}

void set_joint_row_values(const JointFrame& f, const VecX& q, ConstraintRow* rows) {
  int k = 0;
  for_each_value(f, q, [&](double v) { rows[k++].value = v; });
}

bool joint_rows_linear(const JointFrame& f) {
  return f.spec.kind != JointKind::kPrismatic || f.spec.parent < 0;
}

void append_joint_rows(const JointFrame& f, const VecX& q, std::vector<ConstraintRow>& rows) {
  const Vec12 qc = body_q(q, f.spec.child);
  const Vec12 qp = body_q(q, f.spec.parent);
  switch (f.spec.kind) {
    case JointKind::kFree:
      break;
    case JointKind::kBall:
      point_rows(f, qc, qp, f.anchor_c, f.anchor_p, rows);
      break;
    case JointKind::kRevolute:
      point_rows(f, qc, qp, f.anchor_c, f.anchor_p, rows);
      point_rows(f, qc, qp, f.tip_c, f.tip_p, rows);
      break;
    case JointKind::kFixed:
      point_rows(f, qc, qp, f.anchor_c, f.anchor_p, rows);
      frame_rows(f, qc, qp, rows);
      break;
    case JointKind::kPrismatic:
      frame_rows(f, qc, qp, rows);
      offset_rows(f, qc, qp, rows);
      break;
  }
}

}  // namespace abd
