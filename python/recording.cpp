// Recordings as numpy columns: every sample of one topic of an MCAP file
// (ddswarm-record's), decoded with the project's own CDR types, each field a
// column: a number per sample is an array (T,), a Vec3 (T, 3), a field inside
// a sequence of structs (T, N, ...) with N the longest sequence (shorter
// ones padded: NaN, or 0 for 64-bit integers, false for booleans).
#include "python/recording.hpp"

#include <array>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <type_traits>
#include <unordered_map>

#include "common/mcap/mcap_reader.hpp"
#include "common/recorded_sample.hpp"
#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"
#include "message_visit.hpp"

namespace py = pybind11;

namespace ddswarm::py_api {
namespace {

enum class Kind { kFloat, kU64, kI64, kBool, kText };

/// One field's column: its layout, found in a first pass over the samples,
/// then its array, filled in a second.
struct Column {
  std::string name;  ///< "drones.position"
  Kind kind = Kind::kFloat;
  int width = 1;  ///< components per value: 3 for a Vec3, 4 for a Quat or float[4]
  int depth = 0;  ///< sequences around the value
  std::array<std::size_t, 2> extent{0, 0};  ///< the longest sequence at each depth
  py::object array;                         ///< numpy array, or a list of str
  void* data = nullptr;
};

/// The visitor message_visit.hpp's functions call. In the first pass
/// (fill = false) it learns every column's kind, width, depth and extents;
/// in the second it writes each value where it belongs. Columns are found
/// by (enclosing prefix, field name literal), not by building names.
class Columns {
 public:
  bool fill = false;
  std::size_t sample = 0;

  template <class T>
  void value(const char* name, const T& x) {
    if constexpr (std::is_same_v<T, bool>)
      put(name, Kind::kBool, 1,
          [&](Column& c, std::size_t o) { static_cast<bool*>(c.data)[o] = x; });
    else if constexpr (std::is_integral_v<T> && sizeof(T) == 8 && std::is_unsigned_v<T>)
      put(name, Kind::kU64, 1,
          [&](Column& c, std::size_t o) { static_cast<std::uint64_t*>(c.data)[o] = x; });
    else if constexpr (std::is_integral_v<T> && sizeof(T) == 8)
      put(name, Kind::kI64, 1,
          [&](Column& c, std::size_t o) { static_cast<std::int64_t*>(c.data)[o] = x; });
    else
      put(name, Kind::kFloat, 1, [&](Column& c, std::size_t o) {
        static_cast<double*>(c.data)[o] = static_cast<double>(x);
      });
  }
  template <class S>
  void text(const char* name, const S& s) {
    put(name, Kind::kText, 1, [&](Column& c, std::size_t) {
      std::string t;
      if constexpr (std::is_same_v<S, std::string>)
        t = s;
      else
        t = s.to_string();
      py::list l = c.array;
      if (c.depth == 0)
        l[sample] = py::str(t);
      else
        py::list(l[sample]).append(py::str(t));
    });
  }
  template <class T, std::size_t N>
  void array(const char* name, const std::array<T, N>& a) {
    put(name, Kind::kFloat, static_cast<int>(N), [&](Column& c, std::size_t o) {
      for (std::size_t k = 0; k < N; ++k)
        static_cast<double*>(c.data)[o + k] = static_cast<double>(a[k]);
    });
  }
  void vector(const char* name, const msg::Vec3& v) {
    put(name, Kind::kFloat, 3, [&](Column& c, std::size_t o) {
      double* d = static_cast<double*>(c.data) + o;
      d[0] = v.x(), d[1] = v.y(), d[2] = v.z();
    });
  }
  void vector(const char* name, const msg::Quat& q) {
    put(name, Kind::kFloat, 4, [&](Column& c, std::size_t o) {
      double* d = static_cast<double*>(c.data) + o;
      d[0] = q.w(), d[1] = q.x(), d[2] = q.y(), d[3] = q.z();
    });
  }
  template <class S>
  void nested(const char* name, const S& s) {
    const int keep = prefix_;
    prefix_ = prefix(name);
    wire::visit(s, *this);
    prefix_ = keep;
  }
  template <class T>
  void sequence(const char* name, const std::vector<T>& seq) {
    if (depth_ >= 2) throw std::runtime_error(std::string("a sequence three deep: ") + name);
    const int keep = prefix_;
    if constexpr (!std::is_arithmetic_v<T>) prefix_ = prefix(name);
    for (std::size_t k = 0; k < seq.size(); ++k) {
      at_[depth_++] = k;
      if constexpr (std::is_arithmetic_v<T>)
        value(name, seq[k]);
      else
        wire::visit(seq[k], *this);
      --depth_;
    }
    at_[depth_] = 0;
    prefix_ = keep;
  }

  /// After the first pass: every column's array, padded, samples first.
  void allocate(std::size_t samples) {
    samples_ = samples;
    for (auto& c : columns_) {
      std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(samples)};
      for (int d = 0; d < c.depth; ++d) shape.push_back(static_cast<py::ssize_t>(c.extent[d]));
      if (c.width > 1) shape.push_back(c.width);
      std::size_t n = 1;
      for (auto x : shape) n *= static_cast<std::size_t>(x);
      switch (c.kind) {
        case Kind::kText: {
          py::list l(samples);
          if (c.depth > 0)
            for (std::size_t k = 0; k < samples; ++k) l[k] = py::list();
          c.array = l;
          break;
        }
        case Kind::kFloat:
          c.array = alloc<double>(c, shape, n, std::numeric_limits<double>::quiet_NaN());
          break;
        case Kind::kU64:
          c.array = alloc<std::uint64_t>(c, shape, n, 0);
          break;
        case Kind::kI64:
          c.array = alloc<std::int64_t>(c, shape, n, 0);
          break;
        case Kind::kBool:
          c.array = alloc<bool>(c, shape, n, false);
          break;
      }
    }
    fill = true;
  }

  py::dict to_python() const {
    py::dict out;
    for (const auto& c : columns_) out[c.name.c_str()] = c.array;
    return out;
  }

 private:
  struct KeyHash {
    std::size_t operator()(const std::pair<int, const char*>& k) const {
      return std::hash<const void*>()(k.second) ^
             (static_cast<std::size_t>(k.first) * 0x9e3779b97f4a7c15ULL);
    }
  };
  using Key = std::pair<int, const char*>;

  template <class T>
  py::array_t<T> alloc(Column& c, const std::vector<py::ssize_t>& shape, std::size_t n, T pad) {
    py::array_t<T> a(shape);
    std::fill(a.mutable_data(), a.mutable_data() + n, pad);
    c.data = a.mutable_data();
    return a;
  }
  /// The prefix id of field `name` inside the current prefix.
  int prefix(const char* name) {
    const Key k{prefix_, name};
    auto it = prefixes_.find(k);
    if (it != prefixes_.end()) return it->second;
    prefix_names_.push_back(prefix_names_[prefix_] + name + ".");
    return prefixes_[k] = static_cast<int>(prefix_names_.size()) - 1;
  }
  template <class Write>
  void put(const char* name, Kind kind, int width, Write&& write) {
    const Key k{prefix_, name};
    auto it = ids_.find(k);
    if (!fill) {
      if (it == ids_.end()) {
        Column c;
        c.name = prefix_names_[prefix_] + name;
        c.kind = kind;
        c.width = width;
        c.depth = depth_;
        columns_.push_back(std::move(c));
        it = ids_.emplace(k, static_cast<int>(columns_.size()) - 1).first;
      }
      Column& c = columns_[it->second];
      for (int d = 0; d < c.depth; ++d) c.extent[d] = std::max(c.extent[d], at_[d] + 1);
      return;
    }
    Column& c = columns_[it->second];
    std::size_t o = sample;
    for (int d = 0; d < c.depth; ++d) o = o * c.extent[d] + at_[d];
    write(c, o * static_cast<std::size_t>(c.width));
  }

  int prefix_ = 0;
  std::vector<std::string> prefix_names_{""};
  std::unordered_map<Key, int, KeyHash> prefixes_, ids_;
  std::array<std::size_t, 2> at_{0, 0};
  int depth_ = 0;
  std::size_t samples_ = 0;
  std::vector<Column> columns_;
};

/// Opens path, as Python expects of a missing file or one that is not MCAP.
std::unique_ptr<mcap::Reader> open(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    PyErr_SetString(PyExc_FileNotFoundError, (path + ": no such file").c_str());
    throw py::error_already_set();
  }
  try {
    return std::make_unique<mcap::Reader>(path);
  } catch (const std::exception& e) {
    throw py::value_error(e.what());
  }
}

}  // namespace

py::dict recording_info(const std::string& path) {
  auto r = open(path);
  py::dict topics;
  const auto& st = r->statistics();
  for (const auto& [id, ch] : r->channels()) {
    const auto it = st.channel_message_counts.find(id);
    py::dict t;
    t["type"] = r->schemas().count(ch.schema_id) ? r->schemas().at(ch.schema_id).name : "";
    t["count"] = it == st.channel_message_counts.end() ? 0 : it->second;
    topics[ch.topic.c_str()] = t;
  }
  py::dict out;
  out["topics"] = topics;
  out["how_read"] = r->how_read().describe();
  out["truncated"] = r->how_read().truncated;
  out["start_ns"] = st.message_start_time_ns;
  out["end_ns"] = st.message_end_time_ns;
  out["messages"] = st.message_count;
  return out;
}

py::dict read_topic(const std::string& path, const std::string& topic) {
  auto r = open(path);
  std::vector<std::uint16_t> ids;
  std::map<std::uint16_t, ScanLayout> layout;
  for (const auto& [id, ch] : r->channels())
    if (ch.topic == topic) {
      ids.push_back(id);
      layout[id] = channel_scan_layout(*r, ch);
    }
  if (ids.empty()) throw py::key_error(path + ": no topic '" + topic + "' in this recording");
  py::dict out;
  bool known = false;
  for_each_topic_type([&]<class T>() {
    if (known || Topic<T>::name != topic) return;
    known = true;
    Columns cols;
    std::vector<double> log_time_s;
    std::size_t rejected = 0;
    const std::uint64_t start = r->statistics().message_start_time_ns;
    // Two passes over the file: the columns' layout, then their values, so
    // no value is held twice.
    auto pass = [&](bool fill) {
      std::size_t n = 0;
      r->for_each_message([&](const mcap::MessageView& m) {
        if (std::find(ids.begin(), ids.end(), m.channel_id) == ids.end()) return;
        T sample;
        if (!from_cdr(m.data, sample, layout[m.channel_id])) {
          if (!fill) ++rejected;
          return;
        }
        cols.sample = n++;
        wire::visit(sample, cols);
        if (!fill) log_time_s.push_back(static_cast<double>(m.log_time_ns - start) * 1e-9);
      });
    };
    try {
      pass(false);
      cols.allocate(log_time_s.size());
      pass(true);
    } catch (const std::exception& e) {
      throw py::value_error(e.what());
    }
    out = cols.to_python();
    py::array_t<double> t(static_cast<py::ssize_t>(log_time_s.size()));
    std::copy(log_time_s.begin(), log_time_s.end(), t.mutable_data());
    out["log_time_s"] = t;
    out["undecodable"] = rejected;
  });
  if (!known) throw py::key_error("'" + topic + "' is not a ddswarm topic this build decodes");
  return out;
}

}  // namespace ddswarm::py_api
