// ddswarm-gs's DdsCommander for Python. Every blocking call runs on a
// worker thread while the calling thread, the GIL released, looks every
// 50 ms at Python's signals (Ctrl-C) and the call's timeout; either
// interrupts the commander (set_interrupted), which returns within its
// 100 ms polling, and the call raises KeyboardInterrupt or TimeoutError.
// Python's signal handlers run only in the main thread, with the GIL held,
// so a call that simply blocked in C++ could not be interrupted.
#include "python/ground_station.hpp"

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "common/config_error.hpp"
#include "common/convert.hpp"
#include "common/mission.hpp"
#include "common/process.hpp"
#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"
#include "ground_station/dds_commander.hpp"
#include "ground_station/gs_file_config.hpp"

namespace py = pybind11;

namespace ddswarm::py_api {
namespace {

using gs::CommandResult;
using gs::DdsCommander;

[[noreturn]] void raise(PyObject* type, const std::string& message) {
  PyErr_SetString(type, message.c_str());
  throw py::error_already_set();
}

py::dict to_python(const CommandResult& r) {
  py::dict d;
  d["ok"] = r.ok;
  d["message"] = r.message;
  d["missing"] = r.missing;
  py::list rejected;
  for (const auto& [id, why] : r.rejected) rejected.append(py::make_tuple(id, why));
  d["rejected"] = rejected;
  return d;
}

py::dict to_python(const gs::TaskOutcome& o) {
  py::dict d;
  d["ok"] = o.ok;
  d["reason"] = o.reason;
  d["task_time_s"] = o.ok ? o.task_time_s : std::nan("");
  d["wall_time_s"] = o.wall_time_s;
  d["epsilon_m"] = o.epsilon_m;
  d["speed_mps"] = o.speed_mps;
  d["drones"] = o.drones;
  d["collisions_obstacle"] = o.collisions_obstacle;
  d["collisions_drone"] = o.collisions_drone;
  d["collisions_ground"] = o.collisions_ground;
  d["min_inter_drone_m"] = o.min_inter_drone_m;
  d["min_clearance_m"] = o.min_clearance_m;
  d["seed"] = o.seed;
  d["scenario"] = o.scenario;
  d["lost_drones"] = o.lost_drones;
  d["order_mean"] = o.metrics.order_mean;
  d["order_min"] = o.metrics.order_min;
  d["speed_mean_mps"] = o.metrics.speed_mean_mps;
  d["near_misses"] = o.metrics.near_misses;
  d["components_max"] = o.metrics.components_max;
  d["lambda2_min"] = o.metrics.lambda2_min;
  d["line"] = o.line();
  return d;
}

/// A (rows, width) float64 array filled with NaN.
py::array_t<double> nan_array(std::size_t rows, std::size_t width) {
  py::array_t<double> a({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(width)});
  std::fill(a.mutable_data(), a.mutable_data() + rows * width, std::nan(""));
  return a;
}

/// One SwarmState sample as numpy arrays, with the names Recording.swarm_state() gives.
py::dict state_to_python(const msg::SwarmState& s) {
  const auto& drones = s.drones();
  const std::size_t n = drones.size();
  py::dict d;
  d["tick"] = s.tick();
  d["t"] = s.sim_time_s();
  py::array_t<int> ids(static_cast<py::ssize_t>(n));
  py::array_t<std::uint16_t> flags(static_cast<py::ssize_t>(n));
  py::array_t<std::uint8_t> phases(static_cast<py::ssize_t>(n));
  auto pos = nan_array(n, 3), vel = nan_array(n, 3), att = nan_array(n, 4);
  py::list phase_names;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& x = drones[k];
    ids.mutable_data()[k] = x.drone_id();
    flags.mutable_data()[k] = x.flags();
    phases.mutable_data()[k] = x.phase();
    phase_names.append(to_string(static_cast<Phase>(x.phase())));
    double* p = pos.mutable_data() + 3 * k;
    p[0] = x.position().x(), p[1] = x.position().y(), p[2] = x.position().z();
    double* v = vel.mutable_data() + 3 * k;
    v[0] = x.velocity().x(), v[1] = x.velocity().y(), v[2] = x.velocity().z();
    double* q = att.mutable_data() + 4 * k;
    q[0] = x.orientation().w(), q[1] = x.orientation().x(), q[2] = x.orientation().y(),
    q[3] = x.orientation().z();
  }
  // Scans by drone id (index = drone id), padded with NaN to the most rays;
  // a malformed scan (scan_problem) is all NaN.
  std::size_t rays = 0;
  for (const auto& sc : s.scans()) rays = std::max(rays, sc.range_m().size());
  auto ranges = nan_array(n, rays), angles = nan_array(n, rays), elevations = nan_array(n, rays);
  for (const auto& sc : s.scans()) {
    const std::size_t k = sc.drone_id();
    if (k >= n || !scan_problem(sc).empty()) continue;
    for (std::size_t r = 0; r < sc.range_m().size(); ++r) {
      ranges.mutable_data()[k * rays + r] = sc.range_m()[r];
      angles.mutable_data()[k * rays + r] = sc.angle_body_rad()[r];
      elevations.mutable_data()[k * rays + r] = sc.elevation_body_rad()[r];
    }
  }
  d["ids"] = ids;
  d["positions"] = pos;
  d["velocities"] = vel;
  d["attitudes"] = att;
  d["flags"] = flags;
  d["phases"] = phases;
  d["phase_names"] = phase_names;
  d["scan_ranges"] = ranges;
  d["scan_angles"] = angles;
  d["scan_elevations"] = elevations;
  return d;
}

py::dict status_to_python(const gs::SwarmStatus& s) {
  py::dict d;
  d["sim_time_s"] = s.sim_time_s;
  d["real_time_factor"] = s.real_time_factor;
  d["drones_online"] = s.drones_online;
  d["drones_total"] = s.drones_total;
  d["live_agents"] = s.drones_server_hears;
  d["airborne"] = s.airborne;
  d["collisions"] = s.collisions;
  d["failsafe"] = s.failsafe;
  d["mode"] = s.mode;
  d["phases"] = s.task_phase;
  d["d_int_m"] = s.d_int_m;
  py::dict rejected;
  for (const auto& [why, k] : s.rejected) rejected[why.c_str()] = k;
  d["rejected"] = rejected;
  d["commands_applied"] = s.commands_applied;
  d["commands_late"] = s.commands_late;
  d["lockstep_resends"] = s.lockstep_resends;
  d["task"] = s.task;
  d["laws"] = s.laws;
  d["law_faults"] = s.law_faults;
  return d;
}

void check_speed(const char* name, double v) { check_range<double>(name, v, -50.0, 50.0); }

class GroundStation {
 public:
  GroundStation(const std::string& config, std::optional<int> domain, const std::string& secure_dir,
                std::optional<double> timeout_s, bool wait) {
    std::error_code ec;
    if (!config.empty() && !std::filesystem::exists(config, ec))
      raise(PyExc_FileNotFoundError, config + ": cannot open file");
    file_ = gs::load_gs_config(config);
    if (domain) file_.dds.domain_id = *domain;
    if (!secure_dir.empty()) file_.dds.security_dir = secure_dir;
    secure_lease(file_.dds);
    // As ddswarm-gs: over loopback UDP a new ground station hears the
    // server sooner than over shared memory (ground_station/subcommands.cpp).
    if (!file_.gs.shared_memory) file_.dds.shared_memory = false;
    default_security_role(file_.dds, "gs");
    validate_with_overrides(config, [&] { file_.dds.validate(); });
    const double wait_s = timeout_s.value_or(file_.gs.discovery_timeout_s);
    check_range("timeout", wait_s, 0.0, 86400.0);
    gs_ = std::make_unique<DdsCommander>(file_.gs, file_.dds);
    if (!wait) return;
    bool found = blocking(wait_s + 5, [&] { return gs_->wait_for_server(wait_s); });
    double waited = wait_s;
    // As ddswarm-gs does: a server coming up (discovered, not yet heard) is
    // waited for, unless the caller named its own timeout.
    if (!found && !timeout_s && gs_->server_search().state == gs::ServerSearch::State::kComingUp) {
      waited += gs::kServerComingUpS;
      found = blocking(gs::kServerComingUpS + 5,
                       [&] { return gs_->wait_for_server(gs::kServerComingUpS); });
    }
    if (!found)
      raise(PyExc_TimeoutError,
            fmt::format("no simulation server found on domain {} within {:g} s: {}",
                        file_.dds.domain_id, waited, gs_->server_search().found));
  }

  int domain() const { return file_.dds.domain_id; }
  int drones() const { return file_.drones; }
  double default_speed() const { return file_.task.speed_mps; }

  void close() {
    py::gil_scoped_release release;
    gs_.reset();
  }

  void wait_agents(int count, double timeout_s, bool give_up_on_exit, int pid) {
    check_range("timeout", timeout_s, 0.0, 86400.0);
    // give_up: a launcher process of ours that ended (the swarm is gone).
    auto gone = [&] { return give_up_on_exit && pid > 0 && waitpid_gone(pid); };
    const bool up = blocking(timeout_s + 5, [&] {
      return live().wait_for_swarm(count, timeout_s, [&] { return gone(); });
    });
    if (up) return;
    const auto st = live().status();
    const int asked = count < 0 ? st.drones_total : count;
    if (st.drones_server_hears < 0)
      raise(PyExc_TimeoutError,
            fmt::format("timed out after {:g} s: no server heard (this ground station hears "
                        "{}/{} agents online)",
                        timeout_s, st.drones_online, st.drones_total));
    raise(PyExc_TimeoutError,
          fmt::format("timed out after {:g} s: the server hears {} of the {} agents asked for "
                      "(this ground station hears {}/{} online)",
                      timeout_s, st.drones_server_hears, asked, st.drones_online, st.drones_total));
  }

  py::dict takeoff(double altitude_m, bool wait, std::optional<double> timeout) {
    check_range("altitude", altitude_m, 0.0, 1000.0);
    const double t = timeout.value_or(120.0);
    bool airborne = true;
    const auto r = blocking(t + command_s(), [&] {
      auto r = live().takeoff(altitude_m);
      if (r.ok && wait) airborne = live().wait_takeoff_done(live().status().drones_online, t);
      return r;
    });
    if (!airborne)
      raise(PyExc_TimeoutError, fmt::format("not every drone became airborne within {:g} s", t));
    return to_python(r);
  }

  py::dict move(double north, double east, double up, double time_s, bool wait,
                std::optional<double> timeout) {
    check_speed("north", north), check_speed("east", east), check_speed("up", up);
    check_range("time", time_s, 0.0, 86400.0);
    return timed(time_s, wait, timeout,
                 [&] { return live().move(Eigen::Vector3d(east, north, up), time_s); });
  }

  py::dict hold(double time_s, bool wait, std::optional<double> timeout) {
    check_range("time", time_s, 0.0, 86400.0);
    return timed(time_s, wait && time_s > 0, timeout, [&] { return live().hold_for(time_s); });
  }

  py::dict distance(double d_int_m, std::optional<double> timeout) {
    check_range("metres", d_int_m, 0.31, 1000.0);
    return to_python(
        blocking(command_timeout(timeout), [&] { return live().set_distance(d_int_m); }));
  }

  py::dict land(bool wait, std::optional<double> timeout) {
    const double t = timeout.value_or(120.0);
    bool down = true;
    const auto r = blocking(t + command_s(), [&] {
      auto r = live().land();
      if (r.ok && wait) down = live().wait_airborne(0, t);
      return r;
    });
    if (!down) raise(PyExc_TimeoutError, fmt::format("not every drone landed within {:g} s", t));
    return to_python(r);
  }

  py::dict follow(int leader, std::optional<double> timeout) {
    check_range("leader", leader, 0, 1023);
    return to_python(
        blocking(command_timeout(timeout), [&] { return live().follow_leader(leader); }));
  }

  py::dict teleop(double north, double east, double up, std::optional<double> timeout) {
    check_speed("north", north), check_speed("east", east), check_speed("up", up);
    return to_python(blocking(command_timeout(timeout),
                              [&] { return live().teleop(Eigen::Vector3d(east, north, up)); }));
  }

  /// {"command": ..., "outcome": ... (when waited for)}.
  py::dict task(std::optional<double> speed, std::optional<double> epsilon, bool wait,
                std::optional<double> timeout, py::object progress) {
    const double v = speed.value_or(file_.task.speed_mps);
    const double eps = epsilon.value_or(file_.task.epsilon_m);
    check_range("speed", v, 0.0, 50.0);
    check_range("epsilon", eps, 0.0, 10000.0);
    const double t = timeout.value_or(file_.gs.task_timeout_s);
    check_range("timeout", t, 0.0, 1e9);
    std::optional<gs::TaskOutcome> outcome;
    const auto r = blocking(
        t,
        [&] {
          auto r = live().task(v, eps);
          if (r.ok && wait) {
            live().wait_task([&](const std::string& p) { report_progress(p); });
            outcome = live().last_task();
          }
          return r;
        },
        progress, fmt::format("the task: no result within {:g} s", t));
    py::dict d;
    d["command"] = to_python(r);
    if (outcome) d["outcome"] = to_python(*outcome);
    return d;
  }

  py::dict status(double timeout_s) {
    check_range("timeout", timeout_s, 0.0, 86400.0);
    // As `ddswarm-gs status`: the latched task status, then a heartbeat from
    // every agent the server hears live (its phase and law).
    blocking(timeout_s + 1.0 + gs::kAgentHeartbeatsWaitS + 3, [&] {
      if (live().wait_for_status(timeout_s)) {
        live().wait_task_status(std::min(timeout_s, 1.0));
        live().wait_agent_statuses(std::min(timeout_s, gs::kAgentHeartbeatsWaitS));
      }
      return 0;
    });
    return status_to_python(live().status());
  }

  py::dict state(double timeout_s, std::int64_t after_tick) {
    check_range("timeout", timeout_s, 0.0, 86400.0);
    std::optional<msg::SwarmState> got;
    blocking(timeout_s + 3, [&] {
      return live().read_swarm_state(timeout_s, after_tick,
                                     [&](const msg::SwarmState& s) { got = s; });
    });
    if (!got)
      raise(PyExc_TimeoutError, fmt::format("no swarm state received within {:g} s", timeout_s));
    return state_to_python(*got);
  }

 private:
  DdsCommander& live() {
    if (!gs_) throw std::runtime_error("this ground station is closed");
    return *gs_;
  }

  /// A command's bound: every agent's acknowledgement, with its one retry.
  double command_s() const { return file_.gs.ack_timeout_s + 5; }
  double command_timeout(std::optional<double> timeout) const {
    if (timeout) check_range("timeout", *timeout, 0.0, 86400.0);
    return timeout.value_or(command_s());
  }

  /// Our child pid has ended (left unreaped for its owner to collect).
  static bool waitpid_gone(int pid) {
    siginfo_t info{};
    return waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) != 0 ||
           info.si_pid == pid;
  }

  template <class Send>
  py::dict timed(double time_s, bool wait, std::optional<double> timeout, Send&& send) {
    // As the CLI's --wait: until the sim clock has run time_s past the command.
    const double t = timeout.value_or(time_s * 100 + 60);
    bool passed = true;
    const auto r = blocking(t + command_s(), [&] {
      const double t0 = live().status().sim_time_s;
      auto r = send();
      if (r.ok && wait) passed = live().wait_sim_time(t0 + time_s, t);
      return r;
    });
    if (!passed)
      raise(PyExc_TimeoutError,
            fmt::format("{:g} s of sim time did not pass within {:g} s", time_s, t));
    return to_python(r);
  }

  void report_progress(const std::string& p) {
    std::lock_guard<std::mutex> lock(progress_mu_);
    progress_.push_back(p);
  }

  /// Runs f on a worker thread, the GIL released; see the file's comment.
  /// progress (a callable or None) gets report_progress's lines on this thread.
  template <class F>
  auto blocking(double timeout_s, F&& f, py::object progress = py::none(),
                const std::string& timeout_message = "") -> decltype(f()) {
    using namespace std::chrono;
    live().set_interrupted(false);
    auto fut = std::async(std::launch::async, std::forward<F>(f));
    bool interrupted = false, timed_out = false;
    {
      py::gil_scoped_release release;
      const auto end =
          steady_clock::now() + duration_cast<steady_clock::duration>(duration<double>(timeout_s));
      while (fut.wait_for(milliseconds(50)) != std::future_status::ready) {
        {
          py::gil_scoped_acquire acquire;
          if (PyErr_CheckSignals() != 0 || !drain(progress)) interrupted = true;
        }
        if (!interrupted && steady_clock::now() >= end) timed_out = true;
        if (interrupted || timed_out) {
          live().set_interrupted(true);
          fut.wait();
          break;
        }
      }
    }
    live().set_interrupted(false);
    if (!interrupted && !drain(progress)) interrupted = true;
    if (interrupted) {
      fut.wait();
      throw py::error_already_set();  // KeyboardInterrupt, or what the callback raised
    }
    if (timed_out)
      raise(PyExc_TimeoutError, timeout_message.empty()
                                    ? fmt::format("no answer within {:g} s", timeout_s)
                                    : timeout_message);
    return fut.get();
  }

  /// Hands queued progress lines to the callback; false when it raised.
  bool drain(const py::object& progress) {
    std::vector<std::string> lines;
    {
      std::lock_guard<std::mutex> lock(progress_mu_);
      lines.swap(progress_);
    }
    if (progress.is_none()) return true;
    for (const auto& l : lines) {
      PyObject* r = PyObject_CallOneArg(progress.ptr(), py::str(l).ptr());
      if (!r) return false;
      Py_DECREF(r);
    }
    return true;
  }

  gs::GsFileConfig file_;
  std::unique_ptr<DdsCommander> gs_;
  std::mutex progress_mu_;
  std::vector<std::string> progress_;
};

}  // namespace

void bind_ground_station(py::module_& m) {
  m.def(
      "scenario_info",
      [](const std::string& path) {
        std::error_code ec;
        if (!std::filesystem::exists(path, ec))
          raise(PyExc_FileNotFoundError, path + ": cannot open file");
        const auto f = gs::load_gs_config(path);
        py::dict d;
        d["domain"] = f.dds.domain_id;
        d["drones"] = f.drones;
        d["speed_mps"] = f.task.speed_mps;
        return d;
      },
      py::arg("path"),
      "A scenario's domain, drones and task speed, as the ground station reads them");
  py::class_<GroundStation>(m, "GroundStation")
      .def(py::init<const std::string&, std::optional<int>, const std::string&,
                    std::optional<double>, bool>(),
           py::arg("config"), py::arg("domain") = py::none(), py::arg("secure") = "",
           py::arg("timeout") = py::none(), py::arg("wait") = true)
      .def_property_readonly("domain", &GroundStation::domain)
      .def_property_readonly("drones", &GroundStation::drones)
      .def_property_readonly("default_speed", &GroundStation::default_speed)
      .def("close", &GroundStation::close)
      .def("wait_agents", &GroundStation::wait_agents, py::arg("count"), py::arg("timeout"),
           py::arg("give_up_on_exit") = false, py::arg("pid") = 0)
      .def("takeoff", &GroundStation::takeoff, py::arg("altitude"), py::arg("wait"),
           py::arg("timeout"))
      .def("move", &GroundStation::move, py::arg("north"), py::arg("east"), py::arg("up"),
           py::arg("time"), py::arg("wait"), py::arg("timeout"))
      .def("hold", &GroundStation::hold, py::arg("time"), py::arg("wait"), py::arg("timeout"))
      .def("distance", &GroundStation::distance, py::arg("metres"), py::arg("timeout"))
      .def("land", &GroundStation::land, py::arg("wait"), py::arg("timeout"))
      .def("follow", &GroundStation::follow, py::arg("leader"), py::arg("timeout"))
      .def("teleop", &GroundStation::teleop, py::arg("north"), py::arg("east"), py::arg("up"),
           py::arg("timeout"))
      .def("task", &GroundStation::task, py::arg("speed"), py::arg("epsilon"), py::arg("wait"),
           py::arg("timeout"), py::arg("progress"))
      .def("status", &GroundStation::status, py::arg("timeout"))
      .def("state", &GroundStation::state, py::arg("timeout"), py::arg("after_tick") = -1);
}

}  // namespace ddswarm::py_api
