// Joint bindings: the Constraint interface, JointSpec and the JointSet (a Constraint the
// Python World adds with World.add_constraint). States cross as flat (12 n,) arrays.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>
#include <vector>

#include "bindings/bindings.h"
#include "joints/joint_set.h"
#include "solver/constraint.h"

namespace py = pybind11;

namespace abd::bindings {

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
      .def("reset", &JointSet::reset, py::arg("q"));
}

}  // namespace abd::bindings
