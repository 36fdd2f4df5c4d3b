// Joint bindings: the Constraint interface, JointSpec and the JointSet (a Constraint the
// Python World adds with World.add_constraint). States cross as flat (12 n,) arrays.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings/bindings.h"
#include "joints/body_wrench_term.h"
#include "joints/joint_force_term.h"
#include "joints/joint_limit_coordinate.h"
#include "joints/joint_set.h"
#include "solver/constraint.h"

namespace py = pybind11;

namespace abd::bindings {

namespace {

// q must hold 12 entries for every body the joints name.
const VecX& checked_state(const JointSet& joints, const VecX& q) {
  const Eigen::Index n = q.size() / 12;
  bool ok = q.size() % 12 == 0;
  for (int j = 0; j < joints.size() && ok; ++j)
    ok = joints.frame(j).spec.child < n && joints.frame(j).spec.parent < n;
  if (!ok)
    throw std::invalid_argument("joints: q must hold 12 entries for every body (" +
                                std::to_string(q.size()) + " entries given)");
  return q;
}

}  // namespace

void bind_joints(py::module_& m) {
  py::class_<Constraint, std::shared_ptr<Constraint>>(
      m, "Constraint", "Equality constraints every step satisfies exactly (joints).")
      .def_property_readonly("name", &Constraint::name)
      .def_property_readonly("linear", &Constraint::linear)
      .def(
          "violation",
          [](const Constraint& c, const VecX& q) {
            const ConstraintViolation v = c.violation(q);
            return py::make_tuple(v.position, v.angle);
          },
          py::arg("q"), "(largest anchor separation in m, largest misalignment in rad) at q.");

  py::enum_<JointKind>(m, "JointKind")
      .value("free", JointKind::kFree)
      .value("ball", JointKind::kBall)
      .value("revolute", JointKind::kRevolute)
      .value("prismatic", JointKind::kPrismatic)
      .value("fixed", JointKind::kFixed);

  py::class_<JointSpec>(m, "JointSpec", "A joint as given: kind, bodies, world anchor and axis.")
      .def(py::init<>())
      .def_readwrite("kind", &JointSpec::kind)
      .def_readwrite("parent", &JointSpec::parent)
      .def_readwrite("child", &JointSpec::child)
      .def_readwrite("anchor", &JointSpec::anchor)
      .def_readwrite("axis", &JointSpec::axis)
      .def_readwrite("name", &JointSpec::name);

  py::class_<JointSet, Constraint, std::shared_ptr<JointSet>>(m, "JointSet")
      .def(py::init<const SceneData&, const VecX&, const std::vector<JointSpec>&>(),
           py::arg("scene"), py::arg("q0"), py::arg("specs"),
           "Joints with the bodies' flat state q0 (12 n,) as reference; ValueError naming a "
           "bad joint.")
      .def_property_readonly("size", &JointSet::size)
      .def_property_readonly("nq", &JointSet::nq)
      .def_property_readonly("nv", &JointSet::nv)
      .def("q_offset", &JointSet::q_offset, py::arg("joint"))
      .def("v_offset", &JointSet::v_offset, py::arg("joint"))
      .def("positions", &JointSet::positions, py::arg("q"))
      .def("velocities", &JointSet::velocities, py::arg("q"), py::arg("q_dot"))
      .def("reset", &JointSet::reset, py::arg("q"))
      .def(
          "rows",
          [](const JointSet& joints, const VecX& q) {
            std::vector<ConstraintRow> rows;
            joints.linearize(checked_state(joints, q), rows);
            py::list out;
            for (const ConstraintRow& r : rows)
              out.append(py::make_tuple(r.body_a, r.body_b, r.ja, r.jb, r.value));
            return out;
          },
          py::arg("q"),
          "The joints' equality rows linearised at q, in order: (child, parent (−1: the "
          "world), gradient on the child, gradient on the parent, value).")
      .def(
          "values",
          [](const JointSet& joints, const VecX& q) {
            std::vector<ConstraintValue> values;
            joints.values(checked_state(joints, q), values);
            VecX out(static_cast<Eigen::Index>(values.size()));
            for (std::size_t k = 0; k < values.size(); ++k)
              out[static_cast<Eigen::Index>(k)] = values[k].value;
            return out;
          },
          py::arg("q"), "The rows' values at q, in the order of rows().")
      .def(
          "limit_coordinate",
          [](const JointSet& joints, int joint, const VecX& q, bool hessian) {
            if (joint < 0 || joint >= joints.size())
              throw std::invalid_argument("limit_coordinate: joint out of range");
            const JointFrame& f = joints.frame(joint);
            if (f.spec.kind != JointKind::kRevolute && f.spec.kind != JointKind::kPrismatic)
              throw std::invalid_argument("limit_coordinate: a revolute or prismatic joint");
            Vec12 gc, gp;
            Mat24 H;
            const double theta = joint_limit_coordinate(f, checked_state(joints, q), &gc, &gp,
                                                        hessian ? &H : nullptr);
            if (!hessian) return py::tuple(py::make_tuple(theta, gc, gp, py::none()));
            return py::tuple(py::make_tuple(theta, gc, gp, Eigen::MatrixXd(H)));
          },
          py::arg("joint"), py::arg("q"), py::arg("hessian") = true,
          "The coordinate θ the joint's physics and limits act on (angle in (−π, π], or "
          "slide), ∂θ/∂q_child, ∂θ/∂q_parent and ∇²θ over [q_child; q_parent] (24x24; None "
          "with hessian=False, the gradient-only path every Newton assembly takes).");

  py::class_<JointPhysics>(m, "JointPhysics", "A joint's spring, damping, armature, friction "
                                              "loss and limits (MuJoCo's meanings).")
      .def(py::init<>())
      .def_readwrite("stiffness", &JointPhysics::stiffness)
      .def_readwrite("ref", &JointPhysics::ref)
      .def_readwrite("damping", &JointPhysics::damping)
      .def_readwrite("armature", &JointPhysics::armature)
      .def_readwrite("frictionloss", &JointPhysics::frictionloss)
      .def_readwrite("limited", &JointPhysics::limited)
      .def_readwrite("lower", &JointPhysics::lower)
      .def_readwrite("upper", &JointPhysics::upper);

  py::enum_<ActuatorKind>(m, "ActuatorKind")
      .value("motor", ActuatorKind::kMotor)
      .value("position", ActuatorKind::kPosition)
      .value("velocity", ActuatorKind::kVelocity);

  py::class_<ActuatorSpec>(m, "ActuatorSpec")
      .def(py::init<>())
      .def_readwrite("joint", &ActuatorSpec::joint)
      .def_readwrite("kind", &ActuatorSpec::kind)
      .def_readwrite("kp", &ActuatorSpec::kp)
      .def_readwrite("kv", &ActuatorSpec::kv)
      .def_readwrite("gear", &ActuatorSpec::gear)
      .def_readwrite("bias", &ActuatorSpec::bias)
      .def_readwrite("ctrl_limited", &ActuatorSpec::ctrl_limited)
      .def_readwrite("ctrl_lower", &ActuatorSpec::ctrl_lower)
      .def_readwrite("ctrl_upper", &ActuatorSpec::ctrl_upper)
      .def_readwrite("force_limited", &ActuatorSpec::force_limited)
      .def_readwrite("force_lower", &ActuatorSpec::force_lower)
      .def_readwrite("force_upper", &ActuatorSpec::force_upper);

  py::class_<JointForceTerm, EnergyTerm, std::shared_ptr<JointForceTerm>>(m, "JointForceTerm")
      .def(py::init<std::shared_ptr<const JointSet>, const SceneData&,
                    const std::vector<JointPhysics>&, const std::vector<ActuatorSpec>&>(),
           py::arg("joints"), py::arg("scene"), py::arg("physics"), py::arg("actuators"))
      .def_property_readonly(
          "ctrl",
          [](py::object self) {
            JointForceTerm& t = self.cast<JointForceTerm&>();
            VecX& c = t.ctrl();
            // A writable view on the term's controls (world.ctrl[:] = targets).
            return py::array_t<double>({c.size()}, {sizeof(double)}, c.data(), self);
          })
      .def("set_joint_forces", &JointForceTerm::set_joint_forces, py::arg("tau"))
      .def_property_readonly("joint_forces", &JointForceTerm::joint_forces);

  py::class_<BodyWrenchTerm, EnergyTerm, std::shared_ptr<BodyWrenchTerm>>(m, "BodyWrenchTerm")
      .def(py::init<int>(), py::arg("n_bodies"))
      .def("set_wrench", &BodyWrenchTerm::set_wrench, py::arg("body"), py::arg("force"),
           py::arg("torque"), py::arg("x_bar"))
      .def("clear", &BodyWrenchTerm::clear);
}

}  // namespace abd::bindings
