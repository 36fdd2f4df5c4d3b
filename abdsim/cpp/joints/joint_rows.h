// The equality rows of one joint (ABD_NOTES §8). With x = J(x̄) q every row but the
// prismatic offset is linear in the two bodies' q:
//   point    (x_c − x_p)_k = 0 at the anchor            (ball; revolute, fixed with more)
//   point    at the axis tip anchor + lever·t           (revolute: the axis is shared)
//   frame    (A_c ē_c − A_p ē_p)_k = 0 for e1, e2, e3   (fixed, prismatic: no relative turn)
//   offset   (A_p n̄_i)·(x_c − x_p) = 0, i = 1, 2        (prismatic: slide along the axis;
//            bilinear unless the parent is the world)
// Body a of every row is the child, body b the parent (−1: the world, A = I, p = 0).
#pragma once
#include <vector>

#include "joints/joint_spec.h"
#include "solver/constraint.h"

namespace abd {

// The joint's rows at q (q of every body, stacked).
void append_joint_rows(const JointFrame& f, const VecX& q, std::vector<ConstraintRow>& rows);
// Their values alone (the same numbers as the rows' values), in the same order.
void append_joint_values(const JointFrame& f, const VecX& q, std::vector<ConstraintValue>& out);
// Writes the values at q into the joint's rows (rows[0..], as append_joint_rows orders
// them): rows that are linear in q keep their gradients, so only these change.
void set_joint_row_values(const JointFrame& f, const VecX& q, ConstraintRow* rows);
// True when the rows are linear in q.
bool joint_rows_linear(const JointFrame& f);

}  // namespace abd
