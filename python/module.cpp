// _ddswarm: the C++ half of `import ddswarm` (python/ddswarm/ is the rest).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "common/config_error.hpp"
#include "python/ground_station.hpp"
#include "python/process.hpp"
#include "python/recording.hpp"

PYBIND11_MODULE(_ddswarm, m) {
  namespace py = pybind11;
  m.doc() = "ddswarm's C++ libraries for Python (use the ddswarm package)";
  // A bad value is the caller's: ValueError, with the line the CLI prints.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const ddswarm::FieldError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const ddswarm::ConfigError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  m.def("recording_info", &ddswarm::py_api::recording_info, py::arg("path"),
        "Topics, counts and how an MCAP recording was read");
  m.def("read_topic", &ddswarm::py_api::read_topic, py::arg("path"), py::arg("topic"),
        "Every sample of one topic as numpy columns");
  m.def("spawn_session", &ddswarm::py_api::spawn_session, py::arg("argv"), py::arg("log"),
        "Start a program in its own session, dying with the calling thread");
  m.def("free_domain", &ddswarm::py_api::free_domain, py::arg("first"),
        "The first free DDS domain from first up, and the domains passed over");
  m.def("derive_scenario", &ddswarm::py_api::derive_scenario, py::arg("path"), py::arg("sets"),
        py::arg("out"), "Write a scenario with key.path=value overrides applied");
  ddswarm::py_api::bind_ground_station(m);
}
