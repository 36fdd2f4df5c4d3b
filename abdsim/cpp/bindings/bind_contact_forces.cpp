// Contact forces out of the IPC contact term (IpcContactTerm::contact_forces and
// contact_wrenches) as NumPy arrays; bind_contact_term.cpp attaches them to the class.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>

#include "bindings/bind_contact_parts.h"
#include "contact/ipc_contact_term.h"

namespace py = pybind11;

namespace abd::bindings {

py::dict contact_forces_arrays(const IpcContactTerm& term, const VecX& q) {
  const std::vector<contact::ContactForce> forces = term.contact_forces(q);
  const auto k = py::ssize_t(forces.size());
  py::array_t<int> bodies({k, py::ssize_t(2)});
  py::array_t<double> points({k, py::ssize_t(3)}), normals({k, py::ssize_t(3)});
  py::array_t<double> normal_force(k), friction({k, py::ssize_t(3)}), energy(k);
  auto b = bodies.mutable_unchecked<2>();
  auto p = points.mutable_unchecked<2>();
  auto n = normals.mutable_unchecked<2>();
  auto fn = normal_force.mutable_unchecked<1>();
  auto ft = friction.mutable_unchecked<2>();
  auto e = energy.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < k; ++i) {
    const contact::ContactForce& c = forces[size_t(i)];
    b(i, 0) = c.bodies[0];
    b(i, 1) = c.bodies[1];
    fn(i) = c.normal_force;
    e(i) = c.energy;
    for (int j = 0; j < 3; ++j) {
      p(i, j) = c.point[j];
      n(i, j) = c.normal[j];
      ft(i, j) = c.friction[j];
    }
  }
  py::dict d;
  d["bodies"] = bodies;
  d["points"] = points;
  d["normals"] = normals;
  d["normal_force"] = normal_force;
  d["friction_force"] = friction;
  d["barrier_energy"] = energy;
  return d;
}

contact::WrenchMatrix contact_wrenches_array(const IpcContactTerm& term, const VecX& q,
                                             const MatX3& centers) {
  std::vector<Vec3> c(size_t(centers.rows()));
  for (Eigen::Index i = 0; i < centers.rows(); ++i) c[size_t(i)] = centers.row(i).transpose();
  return term.contact_wrenches(q, c);
}

}  // namespace abd::bindings
