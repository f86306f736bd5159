#pragma once
// The recording half of the Python extension: MCAP files as numpy columns.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

namespace ddswarm::py_api {

/// {"topics": {topic: {"type", "count"}}, "how_read", "truncated", "start_ns",
/// "end_ns", "messages"}. FileNotFoundError, or ValueError naming the reason.
pybind11::dict recording_info(const std::string& path);

/// Every sample of topic: {field path: array (samples first)}, plus
/// "log_time_s" (s since the recording's first message) and "undecodable"
/// (samples that did not decode, skipped). KeyError for a topic the file
/// or this build does not have.
pybind11::dict read_topic(const std::string& path, const std::string& topic);

}  // namespace ddswarm::py_api
