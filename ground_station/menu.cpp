#include "ground_station/menu.hpp"

#include <charconv>
#include <cmath>
#include <deque>
#include <exception>
#include <functional>
#include <iomanip>
#include <map>
#include <ostream>
#include <sstream>
#include <string_view>

#include "common/config_error.hpp"

namespace ddswarm::gs {

void MenuOptions::validate() const {
  check_positive("menu.max_speed_mps", max_speed_mps);
  check_positive("menu.max_duration_s", max_duration_s);
  check_positive("menu.min_distance_m", min_distance_m);
  check_range("menu.max_distance_m", max_distance_m, min_distance_m, 1e6);
  check_positive("menu.max_altitude_m", max_altitude_m);
  check_range("menu.default_task_speed_mps", default_task_speed_mps, 1e-9, max_speed_mps);
  check_non_negative("menu.task_epsilon_m", task_epsilon_m);
  check_range("menu.teleop_step_mps", teleop_step_mps, 1e-9, max_speed_mps);
  check_range("menu.max_attempts", max_attempts, 1, 100);
  check_range("menu.max_drone_id", max_drone_id, 0, 65535);
}

namespace {

constexpr const char* kMenu =
    "Please choose an option:\n"
    "1: Takeoff\n"
    "2: Move swarm by velocity and time\n"
    "3: Change distance between drones\n"
    "4: Land\n"
    "5: Follow the leader\n"
    "6: Task\n"
    "0: Quit\n";

constexpr const char* kMenuHelp =
    "Type the option's number; its answers may follow on the same line,\n"
    "e.g. `2 1.2 0.4 0 30` (move north 1.2, east 0.4, up 0 m/s for 30 s) or `1 5`\n"
    "(take off to 5 m; plain `1` uses the agents' default). `q` at a question goes\n"
    "back to the menu.\n";

/// Teleop keys: direction (ENU) of one step of MenuOptions::teleop_step_mps.
const std::map<char, Eigen::Vector3d> kTeleopKeys = {
    {'w', {0, 1, 0}}, {'s', {0, -1, 0}}, {'d', {1, 0, 0}}, {'a', {-1, 0, 0}},
    {'r', {0, 0, 1}}, {'f', {0, 0, -1}}, {'x', {0, 0, 0}}};

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::deque<std::string> split_words(std::string_view s) {
  std::deque<std::string> out;
  std::istringstream is{std::string(s)};
  for (std::string w; is >> w;) out.push_back(w);
  return out;
}

/// Parses a whole finite number; returns the reason it is not one, or "".
std::string parse_double(std::string_view text, double& v) {
  std::string_view s = trim(text);
  if (s.empty()) return "a number is required";
  std::string_view body = s.front() == '+' ? s.substr(1) : s;
  if (s.front() == '+' && !body.empty() && body.front() == '-') body = {};  // "+-1"
  const auto [end, ec] = std::from_chars(body.data(), body.data() + body.size(), v);
  if (ec == std::errc::result_out_of_range) return std::string(s) + ": number out of range";
  if (ec != std::errc() || end != body.data() + body.size() || body.empty())
    return "'" + std::string(s) + "' is not a number";
  if (!std::isfinite(v)) return std::string(s) + ": must be a finite number";
  return "";
}

/// Parses a whole integer; returns the reason it is not one, or "".
std::string parse_int(std::string_view text, long long& v) {
  std::string_view s = trim(text);
  if (s.empty()) return "a whole number is required";
  std::string_view body = s.front() == '+' ? s.substr(1) : s;
  if (s.front() == '+' && !body.empty() && body.front() == '-') body = {};  // "+-1"
  const auto [end, ec] = std::from_chars(body.data(), body.data() + body.size(), v);
  if (ec == std::errc::result_out_of_range) return std::string(s) + ": number out of range";
  if (ec != std::errc() || end != body.data() + body.size() || body.empty())
    return "'" + std::string(s) + "' is not a whole number";
  return "";
}

/// Accepted interval for one answer.
struct Range {
  double lo;
  double hi;
  bool lo_open = false;  ///< lo itself is not accepted
  const char* unit = "";

  std::string check(const std::string& text, double v) const {
    const std::string u = *unit ? std::string(" ") + unit : "";
    if (lo_open ? !(v > lo) : !(v >= lo))
      return text + ": must be " + (lo_open ? "greater than " : "at least ") + num(lo) + u;
    if (!(v <= hi)) return text + ": must be at most " + num(hi) + u;
    return "";
  }
};

enum class Got { kValue, kCancel, kEof };

class Console {
 public:
  Console(Commander& c, LineReader& r, std::ostream& out, const MenuOptions& o)
      : cmd_(c), reader_(r), out_(out), opt_(o) {}

  int run() {
    bool show_menu = true;
    for (;;) {
      if (show_menu) {
        if (opt_.show_status) print_status();
        out_ << kMenu;
      }
      show_menu = true;
      auto line = read("> ");
      if (!line) return end_of_input();
      pending_ = split_words(*line);
      if (pending_.empty()) {
        show_menu = false;
        continue;
      }
      const std::string choice = pending_.front();
      pending_.pop_front();
      bool more = true;
      if (choice == "0" || choice == "quit" || choice == "exit") {
        return quit();
      } else if (choice == "1") {
        more = takeoff();
      } else if (choice == "2") {
        more = move();
      } else if (choice == "3") {
        more = change_distance();
      } else if (choice == "4") {
        report("Land", [&] { return cmd_.land(); });
      } else if (choice == "5") {
        more = follow_leader();
      } else if (choice == "6") {
        more = run_task();
      } else if (choice == "h" || choice == "help" || choice == "?") {
        out_ << kMenuHelp;
      } else {
        out_ << "Unknown option '" << choice << "': choose 0-6 (h for help).\n";
      }
      pending_.clear();
      if (!more) return end_of_input();
    }
  }

 private:
  std::optional<std::string> read(const std::string& prompt) {
    out_.flush();
    return reader_.read(prompt);
  }

  int end_of_input() {
    out_ << (reader_.interrupted() ? "Interrupted" : "End of input")
         << ": leaving the ground station.\n";
    return 0;
  }

  int quit() {
    try {
      const SwarmStatus s = cmd_.status();
      if (s.airborne > 0)
        out_ << s.airborne << " drone(s) still airborne; they keep their last command.\n";
    } catch (const std::exception&) {
      // Quitting must not depend on the swarm answering.
    }
    return 0;
  }

  void print_status() {
    try {
      out_ << format_status(cmd_.status()) << '\n';
    } catch (const std::exception& e) {
      out_ << "[status unavailable: " << e.what() << "]\n";
    }
  }

  /// Sends one command and prints its result; a throwing commander is a failure.
  CommandResult report(const std::string& what, const std::function<CommandResult()>& send) {
    CommandResult r;
    try {
      r = send();
    } catch (const std::exception& e) {
      r = {false, std::string("error: ") + e.what()};
    }
    out_ << what << (r.ok ? ": " : " FAILED: ") << r.message << '\n';
    return r;
  }

  /// Asks until an answer passes check(), at most max_attempts times. An
  /// answer typed after the option on the menu line is used first.
  /// blank_ok: a blank line returns kValue with an empty text (the default).
  Got ask(const std::string& prompt, bool blank_ok,
          const std::function<std::string(const std::string&)>& check) {
    for (int attempt = 1;; ++attempt) {
      std::string text;
      if (!pending_.empty()) {
        text = pending_.front();
        pending_.pop_front();
        out_ << prompt << text << '\n';
      } else {
        auto line = read(prompt);
        if (!line) return Got::kEof;
        text = std::string(trim(*line));
      }
      if (text == "q") {
        out_ << "Cancelled.\n";
        return Got::kCancel;
      }
      const std::string reason = (blank_ok && text.empty()) ? "" : check(text);
      if (reason.empty()) {
        last_text_ = text;
        return Got::kValue;
      }
      pending_.clear();  // later answers on the same line no longer line up
      if (attempt >= opt_.max_attempts) {
        out_ << reason << ". Too many invalid entries; back to the menu.\n";
        return Got::kCancel;
      }
      out_ << reason << ". Try again (q cancels).\n";
    }
  }

  Got ask_number(const std::string& prompt, const Range& range, double& v,
                 std::optional<double> def = std::nullopt) {
    double parsed = 0;
    Got g = ask(prompt, def.has_value(), [&](const std::string& text) {
      std::string why = parse_double(text, parsed);
      return why.empty() ? range.check(text, parsed) : why;
    });
    if (g == Got::kValue) v = last_text_.empty() ? *def : parsed;
    return g;
  }

  Got ask_int(const std::string& prompt, long long lo, long long hi, long long& v) {
    Got g = ask(prompt, false, [&](const std::string& text) {
      std::string why = parse_int(text, v);
      if (!why.empty()) return why;
      if (v < lo || v > hi)
        return text + ": must be between " + std::to_string(lo) + " and " + std::to_string(hi);
      return std::string();
    });
    return g;
  }

  bool takeoff() {
    double altitude_m = 0;
    if (!pending_.empty()) {
      Got g = ask_number("Takeoff altitude in meters: ", {0, opt_.max_altitude_m, false, "m"},
                         altitude_m);
      if (g != Got::kValue) return g != Got::kEof;
    }
    report("Takeoff", [&] { return cmd_.takeoff(altitude_m); });
    return true;
  }

  bool move() {
    const double vmax = opt_.max_speed_mps;
    const Range speed{-vmax, vmax, false, "m/s"};
    double north = 0, east = 0, up = 0, time_s = 0;
    for (auto [prompt, range, value] :
         {std::tuple{"Velocity in North direction: ", speed, &north},
          std::tuple{"Velocity in East direction: ", speed, &east},
          std::tuple{"Velocity in Up direction: ", speed, &up},
          std::tuple{"For time in seconds: ", Range{0, opt_.max_duration_s, true, "s"}, &time_s}}) {
      Got g = ask_number(prompt, range, *value);
      if (g != Got::kValue) return g != Got::kEof;
    }
    const Eigen::Vector3d v_enu(east, north, up);
    report("Move", [&] { return cmd_.move(v_enu, time_s); });
    return true;
  }

  bool change_distance() {
    std::string current = "unknown";
    try {
      current = num(cmd_.status().d_int_m);
    } catch (const std::exception& e) {
      current += std::string(" (") + e.what() + ")";
    }
    out_ << "Current distance between drones: " << current << '\n';
    double d_int_m = 0;
    Got g = ask_number("New distance: ", {opt_.min_distance_m, opt_.max_distance_m, false, "m"},
                       d_int_m);
    if (g != Got::kValue) return g != Got::kEof;
    report("Change distance", [&] { return cmd_.set_distance(d_int_m); });
    return true;
  }

  bool follow_leader() {
    int total = 0;
    try {
      total = cmd_.status().drones_total;
    } catch (const std::exception&) {
      // Unknown swarm size: fall back to max_drone_id.
    }
    const long long hi = total > 0 ? total - 1 : opt_.max_drone_id;
    long long leader = 0;
    Got g = ask_int("Leader drone id (0-" + std::to_string(hi) + "): ", 0, hi, leader);
    if (g != Got::kValue) return g != Got::kEof;
    const int leader_id = static_cast<int>(leader);
    if (!report("Follow the leader", [&] { return cmd_.follow_leader(leader_id); }).ok) {
      // Some drones may have switched; put everyone back in a known state.
      report("Hold", [&] { return cmd_.hold(); });
      return true;
    }
    print_teleop_help();
    const bool more = teleop();
    report("Hold", [&] { return cmd_.hold(); });
    return more;
  }

  void print_teleop_help() {
    const std::string step = num(opt_.teleop_step_mps);
    out_ << "Teleop: each line sets the leader's velocity (ENU, m/s), then press Enter.\n"
         << "  w/s: north/south  d/a: east/west  r/f: up/down  (" << step
         << " m/s per key; keys add up: `wd`, `ww`)\n"
         << "  x: stop    vx vy vz: three numbers, east north up (e.g. `0.5 1 0`)\n"
         << "  h: this help    q: leave (the swarm holds)\n";
  }

  /// Parses one teleop line into a velocity; returns the reason it is bad, or "".
  std::string parse_teleop(const std::string& line, Eigen::Vector3d& v) const {
    auto words = split_words(line);
    if (words.size() == 3) {
      for (int i = 0; i < 3; ++i) {
        std::string why = parse_double(words[i], v[i]);
        if (!why.empty()) return why;
        const double vmax = opt_.max_speed_mps;
        why = Range{-vmax, vmax, false, "m/s"}.check(words[i], v[i]);
        if (!why.empty()) return why;
      }
      return "";
    }
    if (words.size() != 1) return "'" + line + "': type keys (w/a/s/d/r/f/x) or three numbers";
    v.setZero();
    for (char c : words.front()) {
      const auto key = kTeleopKeys.find(c);
      if (key == kTeleopKeys.end())
        return "'" + words.front() + "': unknown key '" + std::string(1, c) + "' (h for help)";
      v += key->second * opt_.teleop_step_mps;
    }
    if (v.cwiseAbs().maxCoeff() > opt_.max_speed_mps + 1e-9)
      return "'" + words.front() + "': faster than " + num(opt_.max_speed_mps) + " m/s";
    return "";
  }

  /// The teleop loop; returns false at end of input.
  bool teleop() {
    int bad = 0;
    for (;;) {
      if (opt_.show_status) print_status();
      auto line = read("teleop> ");
      if (!line) return false;
      const std::string text(trim(*line));
      if (text.empty()) continue;
      if (text == "q") return true;
      if (text == "h" || text == "?" || text == "help") {
        print_teleop_help();
        continue;
      }
      Eigen::Vector3d v;
      const std::string why = parse_teleop(text, v);
      if (!why.empty()) {
        if (++bad >= opt_.max_attempts) {
          out_ << why << ". Too many invalid entries; leaving follow mode.\n";
          return true;
        }
        out_ << why << ".\n";
        continue;
      }
      bad = 0;
      report("Leader velocity E " + num(v.x()) + " N " + num(v.y()) + " U " + num(v.z()) + " m/s",
             [&] { return cmd_.teleop(v); });
    }
  }

  bool run_task() {
    double speed = 0;
    Got g = ask_number("Task speed in m/s [" + num(opt_.default_task_speed_mps) + "]: ",
                       {0, opt_.max_speed_mps, true, "m/s"}, speed, opt_.default_task_speed_mps);
    if (g != Got::kValue) return g != Got::kEof;
    if (!report("Task", [&] { return cmd_.task(speed, opt_.task_epsilon_m); }).ok) return true;
    out_ << "Task running at " << num(speed) << " m/s...\n";
    std::string result;
    try {
      result = cmd_.wait_task([&](const std::string& progress) {
        out_ << "  " << progress << '\n' << std::flush;
      });
    } catch (const std::exception& e) {
      result = std::string("error: ") + e.what();
    }
    out_ << "Task result: " << result << '\n';
    return true;
  }

  Commander& cmd_;
  LineReader& reader_;
  std::ostream& out_;
  const MenuOptions& opt_;
  std::deque<std::string> pending_;  ///< answers typed after the option on the menu line
  std::string last_text_;            ///< text of the last accepted answer
};

}  // namespace

std::string format_status(const SwarmStatus& s) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(1) << "[sim " << s.sim_time_s << " s | ";
  if (std::isfinite(s.real_time_factor))
    os << std::setprecision(2) << 'x' << s.real_time_factor << " real time | ";
  else
    os << "x? real time | ";
  os << "drones " << s.drones_online << '/' << s.drones_total << " online | " << s.airborne
     << " airborne | " << s.collisions << " collisions";
  if (s.failsafe > 0) os << " | " << s.failsafe << " in failsafe";
  os.unsetf(std::ios::floatfield);
  os << std::setprecision(6);
  if (!s.mode.empty()) os << " | " << s.mode;
  if (!s.task_phase.empty()) os << " | phase " << s.task_phase;
  if (!s.task.empty()) os << " | task " << s.task;
  os << " | D_int " << s.d_int_m << " m";
  // The laws only when the swarm flies more than the thesis's.
  if (!s.laws.empty() && s.laws.find(',') == std::string::npos &&
      s.laws.find(" thesis") == std::string::npos)
    os << " | law " << s.laws.substr(s.laws.find(' ') + 1);
  else if (s.laws.find(',') != std::string::npos)
    os << " | laws " << s.laws;
  if (!s.law_faults.empty())
    os << " | " << s.law_faults.size() << " law fault" << (s.law_faults.size() > 1 ? "s" : "")
       << ": " << s.law_faults.front();
  os << "]";
  return os.str();
}

std::string format_rejections(const SwarmStatus& s) {
  if (s.rejected.empty()) return "rejected samples: unknown (no server or agent heard)";
  std::uint64_t total = 0;
  std::string parts;
  for (const auto& [reason, n] : s.rejected) {
    total += n;
    parts += (parts.empty() ? "" : ", ") + reason + " " + std::to_string(n);
  }
  return "rejected samples: " + std::to_string(total) + " (" + parts + ")";
}

std::string format_commands(const SwarmStatus& s) {
  if (s.commands_applied < 0) return "";
  std::string line = "commands: " + std::to_string(s.commands_applied) + " applied, " +
                     std::to_string(s.commands_late) + " late (answered after their step)";
  if (s.lockstep_resends > 0)
    line += "; " + std::to_string(s.lockstep_resends) + " ticks published again (answers missing)";
  return line;
}

int run_menu(Commander& commander, LineReader& reader, std::ostream& out,
             const MenuOptions& options) {
  options.validate();
  return Console(commander, reader, out, options).run();
}

}  // namespace ddswarm::gs
