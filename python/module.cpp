// _ddswarm: the C++ half of `import ddswarm` (python/ddswarm/ is the rest).
#include <pybind11/pybind11.h>

#include "python/recording.hpp"

PYBIND11_MODULE(_ddswarm, m) {
  m.doc() = "ddswarm's C++ libraries for Python (use the ddswarm package)";
  m.def("recording_info", &ddswarm::py_api::recording_info, pybind11::arg("path"),
        "Topics, counts and how an MCAP recording was read");
  m.def("read_topic", &ddswarm::py_api::read_topic, pybind11::arg("path"), pybind11::arg("topic"),
        "Every sample of one topic as numpy columns");
}
