#pragma once
// The ground-station half of the Python extension: ddswarm-gs's DDS
// commander as a Python class, every mission command a method.
#include <pybind11/pybind11.h>

namespace ddswarm::py_api {

/// Adds _ddswarm.GroundStation (and what it returns) to m.
void bind_ground_station(pybind11::module_& m);

}  // namespace ddswarm::py_api
