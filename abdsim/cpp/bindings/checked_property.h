// Settings fields bound as properties whose setters refuse NaN and infinity: the C++ range
// checks (d_hat > 0, ...) let +inf through, and a non-finite setting only shows up later as
// NaN energies or a stalled solve.
#pragma once
#include <pybind11/pybind11.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace abd::bindings {

template <class C, class... Options>
void def_finite(pybind11::class_<C, Options...>& cls, const char* type_name, const char* name,
                double C::*field, const char* doc = "") {
  const std::string what = std::string(type_name) + "." + name;
  cls.def_property(
      name, [field](const C& c) { return c.*field; },
      [field, what](C& c, double v) {
        if (!std::isfinite(v))
          throw std::invalid_argument(what + " must be finite, got " + std::to_string(v));
        c.*field = v;
      },
      doc);
}

}  // namespace abd::bindings
