// Recordings as numpy columns: every sample of one topic of an MCAP file
// (ddswarm-record's), decoded with the project's own CDR types, each field a
// column: a number per sample is an array (T,), a Vec3 (T, 3), a field inside
// a sequence of structs (T, N, ...) with N the longest sequence (shorter
// ones padded: NaN, or 0 for 64-bit integers and booleans).
#include "python/recording.hpp"

#include <array>
#include <cstring>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <type_traits>

#include "common/mcap/mcap_reader.hpp"
#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"
#include "message_visit.hpp"

namespace py = pybind11;

namespace ddswarm::py_api {
namespace {

enum class Kind { kFloat, kU64, kI64, kBool, kText };

/// One field's values over the samples.
struct Column {
  Kind kind = Kind::kFloat;
  int width = 1;  ///< components per value: 3 for a Vec3, 4 for a Quat or float[4]
  int depth = 0;  ///< sequences around the value
  std::array<std::size_t, 2> extent{0, 0};  ///< longest sequence at each depth
  struct Cell {
    std::size_t sample;
    std::array<std::size_t, 2> at;
    std::size_t first;  ///< index of its first component in values / texts
  };
  std::vector<Cell> cells;
  std::vector<double> f;
  std::vector<std::uint64_t> u;
  std::vector<std::int64_t> i;
  std::vector<std::string> texts;
};

/// The visitor message_visit.hpp's functions call: puts each field of the
/// current sample into its column.
class Columns {
 public:
  std::size_t sample = 0;

  template <class T>
  void value(const char* name, const T& x) {
    if constexpr (std::is_same_v<T, bool>)
      put(name, Kind::kBool, 1, [&](Column& c) { c.u.push_back(x ? 1 : 0); });
    else if constexpr (std::is_integral_v<T> && sizeof(T) == 8 && std::is_unsigned_v<T>)
      put(name, Kind::kU64, 1, [&](Column& c) { c.u.push_back(x); });
    else if constexpr (std::is_integral_v<T> && sizeof(T) == 8)
      put(name, Kind::kI64, 1, [&](Column& c) { c.i.push_back(x); });
    else
      put(name, Kind::kFloat, 1, [&](Column& c) { c.f.push_back(static_cast<double>(x)); });
  }
  template <class S>
  void text(const char* name, const S& s) {
    std::string t;
    if constexpr (std::is_same_v<S, std::string>) t = s;
    else t = s.to_string();
    put(name, Kind::kText, 1, [&](Column& c) { c.texts.push_back(std::move(t)); });
  }
  template <class T, std::size_t N>
  void array(const char* name, const std::array<T, N>& a) {
    put(name, Kind::kFloat, static_cast<int>(N), [&](Column& c) {
      for (const auto& x : a) c.f.push_back(static_cast<double>(x));
    });
  }
  void vector(const char* name, const msg::Vec3& v) {
    put(name, Kind::kFloat, 3, [&](Column& c) { c.f.insert(c.f.end(), {v.x(), v.y(), v.z()}); });
  }
  void vector(const char* name, const msg::Quat& q) {
    put(name, Kind::kFloat, 4, [&](Column& c) { c.f.insert(c.f.end(), {q.w(), q.x(), q.y(), q.z()}); });
  }
  template <class S>
  void nested(const char* name, const S& s) {
    const std::size_t keep = prefix_.size();
    prefix_ += std::string(name) + ".";
    wire::visit(s, *this);
    prefix_.resize(keep);
  }
  template <class T>
  void sequence(const char* name, const std::vector<T>& seq) {
    if (depth_ >= 2) throw std::runtime_error(std::string("a sequence three deep: ") + name);
    const std::size_t keep = prefix_.size();
    for (std::size_t k = 0; k < seq.size(); ++k) {
      at_[depth_] = k;
      ++depth_;
      if constexpr (std::is_arithmetic_v<T>) {
        value(name, seq[k]);
      } else {
        prefix_ += std::string(name) + ".";
        wire::visit(seq[k], *this);
        prefix_.resize(keep);
      }
      --depth_;
    }
    at_[depth_] = 0;
    if (seq.empty()) touch(name);
  }

  /// Each column as a numpy array (text: a list of str), samples first.
  py::dict to_python(std::size_t samples) const {
    py::dict out;
    for (const auto& name : order_) {
      const Column& c = columns_.at(name);
      std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(samples)};
      for (int d = 0; d < c.depth; ++d) shape.push_back(static_cast<py::ssize_t>(c.extent[d]));
      if (c.width > 1) shape.push_back(c.width);
      std::size_t per_sample = 1;
      for (std::size_t k = 1; k < shape.size(); ++k) per_sample *= static_cast<std::size_t>(shape[k]);
      auto offset = [&](const Column::Cell& cell) {
        std::size_t o = cell.sample;
        for (int d = 0; d < c.depth; ++d) o = o * c.extent[d] + cell.at[d];
        return o * static_cast<std::size_t>(c.width);
      };
      if (c.kind == Kind::kText) {
        if (c.depth == 0 && c.width == 1) {
          py::list l(samples);
          for (const auto& cell : c.cells) l[cell.sample] = c.texts[cell.first];
          out[name.c_str()] = l;
        } else {
          py::list l;  // text inside sequences: one list per sample, in order
          std::vector<py::list> per(samples);
          for (const auto& cell : c.cells) per[cell.sample].append(c.texts[cell.first]);
          for (auto& p : per) l.append(p);
          out[name.c_str()] = l;
        }
        continue;
      }
      auto fill = [&](auto* data, auto pad, const auto& src) {
        std::fill(data, data + samples * per_sample, pad);
        for (const auto& cell : c.cells)
          for (int w = 0; w < c.width; ++w) data[offset(cell) + w] = src[cell.first + w];
      };
      if (c.kind == Kind::kFloat) {
        py::array_t<double> a(shape);
        fill(a.mutable_data(), std::numeric_limits<double>::quiet_NaN(), c.f);
        out[name.c_str()] = a;
      } else if (c.kind == Kind::kU64) {
        py::array_t<std::uint64_t> a(shape);
        fill(a.mutable_data(), std::uint64_t{0}, c.u);
        out[name.c_str()] = a;
      } else if (c.kind == Kind::kI64) {
        py::array_t<std::int64_t> a(shape);
        fill(a.mutable_data(), std::int64_t{0}, c.i);
        out[name.c_str()] = a;
      } else {
        py::array_t<bool> a(shape);
        bool* d = a.mutable_data();
        std::fill(d, d + samples * per_sample, false);
        for (const auto& cell : c.cells) d[offset(cell)] = c.u[cell.first] != 0;
        out[name.c_str()] = a;
      }
    }
    return out;
  }

 private:
  Column& column(const std::string& full, Kind kind, int width) {
    auto it = columns_.find(full);
    if (it == columns_.end()) {
      it = columns_.emplace(full, Column{}).first;
      it->second.kind = kind;
      it->second.width = width;
      it->second.depth = depth_;
      order_.push_back(full);
    }
    return it->second;
  }
  /// An empty sequence still names its column (of extent 0 so far).
  void touch(const char* name) {
    (void)name;
  }
  template <class Put>
  void put(const char* name, Kind kind, int width, Put&& put_values) {
    Column& c = column(prefix_ + name, kind, width);
    const std::size_t first = kind == Kind::kText ? c.texts.size()
                              : kind == Kind::kFloat ? c.f.size()
                              : kind == Kind::kI64   ? c.i.size()
                                                     : c.u.size();
    c.cells.push_back({sample, at_, first});
    for (int d = 0; d < c.depth; ++d) c.extent[d] = std::max(c.extent[d], at_[d] + 1);
    put_values(c);
  }

  std::string prefix_;
  std::array<std::size_t, 2> at_{0, 0};
  int depth_ = 0;
  std::map<std::string, Column> columns_;
  std::vector<std::string> order_;
};

/// Deserialises one recorded CDR payload (encapsulation header included).
template <class T>
bool from_cdr(std::span<const std::uint8_t> bytes, T& sample) {
  if constexpr (std::is_same_v<T, msg::SwarmState>) {
    return decode_swarm_state(bytes.data(), bytes.size(), sample);
  } else {
    typename Topic<T>::PubSub type;
    eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
    std::memcpy(payload.data, bytes.data(), bytes.size());
    payload.length = static_cast<std::uint32_t>(bytes.size());
    try {
      return type.deserialize(&payload, &sample);
    } catch (const std::exception&) {  // fastcdr throws on truncated data
      return false;
    }
  }
}

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
  for (const auto& [id, ch] : r->channels())
    if (ch.topic == topic) ids.push_back(id);
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
    try {
      r->for_each_message([&](const mcap::MessageView& m) {
        if (std::find(ids.begin(), ids.end(), m.channel_id) == ids.end()) return;
        T sample;
        if (!from_cdr(m.data, sample)) {
          ++rejected;
          return;
        }
        cols.sample = log_time_s.size();
        wire::visit(sample, cols);
        log_time_s.push_back(static_cast<double>(m.log_time_ns - start) * 1e-9);
      });
    } catch (const std::exception& e) {
      throw py::value_error(e.what());
    }
    out = cols.to_python(log_time_s.size());
    py::array_t<double> t(static_cast<py::ssize_t>(log_time_s.size()));
    std::copy(log_time_s.begin(), log_time_s.end(), t.mutable_data());
    out["log_time_s"] = t;
    out["undecodable"] = rejected;
  });
  if (!known) throw py::key_error("'" + topic + "' is not a ddswarm topic this build decodes");
  return out;
}

}  // namespace ddswarm::py_api
