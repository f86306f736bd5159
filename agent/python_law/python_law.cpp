// Python swarm laws (agent.law.type: python): a law plug-in that runs a
// class from a .py file in Debian's Python 3, embedded in the agent. Only
// agents that fly a Python law load it, and with it the interpreter.
//
// The Python side (docs/laws.md, "A law in Python"):
//   class MyLaw:
//       PARAMS = {"gain": 0.4}               # every parameter and its default
//       uses_obstacle_term = True            # optional
//       def __init__(self, params, seed, context): ...
//       def step(self, obs):                 # -> velocity [vx, vy, vz] (m/s, ENU)
//           ...                              #    or (velocity, yaw_rate)
// obs carries numpy arrays (obs.p, obs.v, obs.q, obs.peers_p N×3, ...).
#include <dlfcn.h>
#include <pybind11/embed.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdio>
#include <filesystem>
#include <mutex>

#include "ddswarm/law.hpp"

namespace py = pybind11;
using namespace ddswarm::law;

namespace {

/// One tick's observation as Python sees it: numpy arrays, copied. It owns
/// its peers and rays, so a law may keep it past the call.
struct PyObservation {
  explicit PyObservation(const Observation& obs)
      : o(obs),
        peer_list(obs.peers.begin(), obs.peers.end()),
        ray_list(obs.rays.begin(), obs.rays.end()) {
    o.peers = peer_list;
    o.rays = ray_list;
  }
  PyObservation(const PyObservation& other) : PyObservation(other.o) {}
  Observation o;
  std::vector<Peer> peer_list;
  std::vector<Ray> ray_list;
  py::array_t<double> vec(const Eigen::Vector3d& v) const {
    py::array_t<double> a(3);
    auto m = a.mutable_unchecked<1>();
    for (int k = 0; k < 3; ++k) m(k) = v[k];
    return a;
  }
  py::array_t<double> peers(int what) const {  // 0 p, 1 v
    py::array_t<double> a({static_cast<py::ssize_t>(o.peers.size()), py::ssize_t{3}});
    auto m = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < o.peers.size(); ++i)
      for (int k = 0; k < 3; ++k)
        m(static_cast<py::ssize_t>(i), k) =
            what == 0 ? o.peers[i].p_world[k] : o.peers[i].v_world[k];
    return a;
  }
  template <class F>
  py::array_t<double> per_peer(F f) const {
    py::array_t<double> a(static_cast<py::ssize_t>(o.peers.size()));
    auto m = a.mutable_unchecked<1>();
    for (std::size_t i = 0; i < o.peers.size(); ++i) m(static_cast<py::ssize_t>(i)) = f(o.peers[i]);
    return a;
  }
  template <class F>
  py::array_t<double> per_ray(F f) const {
    py::array_t<double> a(static_cast<py::ssize_t>(o.rays.size()));
    auto m = a.mutable_unchecked<1>();
    for (std::size_t i = 0; i < o.rays.size(); ++i) m(static_cast<py::ssize_t>(i)) = f(o.rays[i]);
    return a;
  }
};

}  // namespace

PYBIND11_EMBEDDED_MODULE(ddswarm_law, m) {
  m.doc() = "What a ddswarm swarm law sees each control tick (docs/laws.md)";
  py::class_<PyObservation>(m, "Observation")
      .def_property_readonly("drone_id", [](const PyObservation& s) { return s.o.drone_id; })
      .def_property_readonly("tick", [](const PyObservation& s) { return s.o.tick; })
      .def_property_readonly("sim_time_s", [](const PyObservation& s) { return s.o.sim_time_s; })
      .def_property_readonly("dt_s", [](const PyObservation& s) { return s.o.dt_s; })
      .def_property_readonly("p", [](const PyObservation& s) { return s.vec(s.o.p_world); })
      .def_property_readonly("v", [](const PyObservation& s) { return s.vec(s.o.v_world); })
      .def_property_readonly("q",
                             [](const PyObservation& s) {  // w, x, y, z
                               py::array_t<double> a(4);
                               auto m = a.mutable_unchecked<1>();
                               m(0) = s.o.q_world_body.w(), m(1) = s.o.q_world_body.x();
                               m(2) = s.o.q_world_body.y(), m(3) = s.o.q_world_body.z();
                               return a;
                             })
      .def_property_readonly(
          "peers_id",
          [](const PyObservation& s) {
            return s.per_peer([](const Peer& p) { return static_cast<double>(p.id); });
          })
      .def_property_readonly("peers_p", [](const PyObservation& s) { return s.peers(0); })
      .def_property_readonly("peers_v", [](const PyObservation& s) { return s.peers(1); })
      .def_property_readonly(
          "peers_age_s",
          [](const PyObservation& s) { return s.per_peer([](const Peer& p) { return p.age_s; }); })
      .def_property_readonly(
          "rays_range_m",
          [](const PyObservation& s) { return s.per_ray([](const Ray& r) { return r.range_m; }); })
      .def_property_readonly("rays_hit",
                             [](const PyObservation& s) {
                               return s.per_ray([](const Ray& r) { return r.hit ? 1.0 : 0.0; });
                             })
      .def_property_readonly("rays_yaw_rad",
                             [](const PyObservation& s) {
                               return s.per_ray([](const Ray& r) { return r.yaw_body_rad; });
                             })
      .def_property_readonly("rays_pitch_rad",
                             [](const PyObservation& s) {
                               return s.per_ray([](const Ray& r) { return r.pitch_body_rad; });
                             })
      .def_property_readonly("phase",
                             [](const PyObservation& s) { return static_cast<int>(s.o.phase); })
      .def_property_readonly("mission_velocity",
                             [](const PyObservation& s) { return s.vec(s.o.mission_velocity); })
      .def_property_readonly("goal", [](const PyObservation& s) { return s.vec(s.o.goal_world); })
      .def_property_readonly("inter_distance_m",
                             [](const PyObservation& s) { return s.o.inter_distance_m; })
      .def_property_readonly("altitude_target_m",
                             [](const PyObservation& s) { return s.o.altitude_target_m; })
      .def_property_readonly("max_speed_mps",
                             [](const PyObservation& s) { return s.o.max_speed_mps; });
}

namespace {

/// The interpreter, started once per process; the GIL is released between calls.
void start_python() {
  static std::once_flag once;
  std::call_once(once, [] {
    // Python's C extensions (numpy) expect libpython's symbols global; this
    // plug-in itself was loaded with RTLD_LOCAL.
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&Py_Initialize), &info) && info.dli_fname)
      dlopen(info.dli_fname, RTLD_NOW | RTLD_GLOBAL | RTLD_NOLOAD);
    py::initialize_interpreter();
    PyEval_SaveThread();
  });
}

/// A Python exception as one line for the fault, and in full (traceback) on stderr.
std::string python_error(py::error_already_set& e, const std::string& where,
                         bool traceback = true) {
  if (traceback) {
    std::fprintf(stderr, "ddswarm python law: %s: %s\n", where.c_str(), e.what());
    std::fflush(stderr);
  }
  std::string head = e.what();
  if (auto nl = head.find('\n'); nl != std::string::npos) head = head.substr(0, nl);
  return head;
}

class PythonLaw final : public SwarmLaw {
 public:
  PythonLaw(py::object obj, bool obstacle_term, std::string name)
      : obj_(std::move(obj)), obstacle_term_(obstacle_term), name_(std::move(name)) {}
  ~PythonLaw() override {
    py::gil_scoped_acquire gil;
    obj_ = py::object();
  }

  Command step(const Observation& o) override {
    py::gil_scoped_acquire gil;
    try {
      py::object r = obj_.attr("step")(PyObservation(o));
      py::object v = r;
      double yaw = 0;
      if (py::isinstance<py::tuple>(r) && py::len(r) == 2) {
        v = r[py::int_(0)];
        yaw = r[py::int_(1)].cast<double>();
      }
      auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(v);
      if (!a || a.size() != 3)
        throw std::runtime_error(name_ + ".step returned " +
                                 py::str(py::repr(r)).cast<std::string>() +
                                 ", not a velocity of 3 numbers (or (velocity, yaw_rate))");
      return {Eigen::Vector3d(a.at(0), a.at(1), a.at(2)), yaw};
    } catch (py::error_already_set& e) {
      throw std::runtime_error("Python " + python_error(e, name_ + ".step"));
    } catch (const py::cast_error& e) {
      throw std::runtime_error(name_ + ".step: " + e.what());
    }
  }
  bool uses_obstacle_term() const override { return obstacle_term_; }

 private:
  py::object obj_;
  bool obstacle_term_;
  std::string name_;
};

std::unique_ptr<SwarmLaw> make(Params& p, Rng rng, const LawContext& ctx) {
  std::string prefix = p.prefix();  // agent.law.params
  if (prefix.size() > 7 && prefix.ends_with(".params")) prefix.resize(prefix.size() - 7);
  const std::string file = p.text("ddswarm:module", "");
  const std::string cls = p.text("ddswarm:class", "");
  if (file.empty())
    throw ParamError(prefix + ".module", "\"\"", "a Python law needs the path of its .py file");
  if (cls.empty())
    throw ParamError(prefix + ".class", "\"\"", "a Python law needs the name of its class");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw ParamError(prefix + ".module", file, "no such file");
  start_python();
  py::gil_scoped_acquire gil;
  const std::string where = file + ":" + cls;
  try {
    const std::filesystem::path path = std::filesystem::absolute(file);
    py::module_::import("ddswarm_law");  // registers Observation
    py::module_ sys = py::module_::import("sys");
    py::list sys_path = sys.attr("path");
    const std::string dir = path.parent_path().string();
    if (!sys_path.contains(dir)) sys_path.insert(0, dir);
    py::module_ util = py::module_::import("importlib.util");
    const std::string mod_name = "ddswarm_law_" + path.stem().string();
    py::object modules = sys.attr("modules");
    py::object mod;
    if (modules.contains(mod_name)) {
      mod = modules[py::str(mod_name)];
    } else {
      py::object spec = util.attr("spec_from_file_location")(mod_name, path.string());
      mod = util.attr("module_from_spec")(spec);
      modules[py::str(mod_name)] = mod;
      spec.attr("loader").attr("exec_module")(mod);
    }
    if (!py::hasattr(mod, cls.c_str()))
      throw ParamError(prefix + ".class", cls, "no such class in " + file);
    py::object klass = mod.attr(cls.c_str());
    // Every parameter the class declares, read with its default's type.
    py::dict params;
    if (py::hasattr(klass, "PARAMS")) {
      for (auto item : py::dict(klass.attr("PARAMS"))) {
        const std::string key = py::str(item.first);
        py::handle def = item.second;
        if (py::isinstance<py::bool_>(def))
          params[py::str(key)] = p.flag(key, def.cast<bool>());
        else if (py::isinstance<py::int_>(def))
          params[py::str(key)] = p.integer(key, def.cast<int>(), INT32_MIN, INT32_MAX);
        else if (py::isinstance<py::float_>(def))
          params[py::str(key)] = p.number(key, def.cast<double>());
        else
          params[py::str(key)] = p.text(key, py::str(def));
      }
    }
    p.finish();
    py::dict context;
    context["drone_id"] = ctx.drone_id;
    context["num_drones"] = ctx.num_drones;
    context["inter_distance_m"] = ctx.inter_distance_m;
    context["max_speed_mps"] = ctx.max_speed_mps;
    context["control_period_s"] = ctx.control_period_s;
    py::object obj = klass(params, rng.next(), context);
    if (!py::hasattr(obj, "step"))
      throw ParamError(prefix + ".class", cls, "has no step(self, obs) method");
    const bool obstacle_term =
        py::hasattr(obj, "uses_obstacle_term") ? obj.attr("uses_obstacle_term").cast<bool>() : true;
    return std::make_unique<PythonLaw>(std::move(obj), obstacle_term, cls);
  } catch (py::error_already_set& e) {
    // One line, as every configuration error (the law is built before anything flies).
    throw ParamError(prefix + ".class", cls, "Python " + python_error(e, where, false));
  }
}

}  // namespace

DDSWARM_LAW_PLUGIN(make)
