#include "experiment/report.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace ddswarm::gs {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

const std::vector<std::string> kColumns = {"set_name",
                                           "run_index",
                                           "seed",
                                           "drones",
                                           "d_int_m",
                                           "speed_mps",
                                           "sensor_function",
                                           "mode",
                                           "ok",
                                           "failure_reason",
                                           "task_time_s",
                                           "wall_time_s",
                                           "collisions_obstacle",
                                           "collisions_drone",
                                           "collisions_ground",
                                           "min_inter_drone_m",
                                           "min_clearance_m",
                                           "params"};

/// After params, so that the older columns keep their positions; optional
/// when reading (files written before them).
const std::vector<std::string> kMetricColumns = {
    "order_mean",     "order_min",   "speed_mean_mps",  "near_misses",
    "components_max", "lambda2_min", "metrics_range_m", "near_miss_m"};

std::string header_line() {
  std::string h;
  for (const auto& c : kColumns) h += (h.empty() ? "" : ",") + c;
  for (const auto& c : kMetricColumns) h += "," + c;
  return h;
}

std::runtime_error io_error(const std::string& path, const std::string& what, int err) {
  return std::runtime_error(path + ": " + what + ": " + std::strerror(err));
}

// ---- CSV writing ----

std::string csv_field(const std::string& s) {
  const bool quote = s.find_first_of(",\"\r\n") != std::string::npos ||
                     (!s.empty() && (s.front() == ' ' || s.back() == ' '));
  if (!quote) return s;
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + '"';
}

template <class T>
std::string number_text(T v) {
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, end);
}

std::string escape_param(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\\' || c == ';' || c == '=') out += '\\';
    out += c;
  }
  return out;
}

std::string encode_params(const std::map<std::string, std::string>& params) {
  std::string out;
  for (const auto& [k, v] : params)
    out += (out.empty() ? "" : ";") + escape_param(k) + "=" + escape_param(v);
  return out;
}

std::string csv_row(const RunRecord& r) {
  const std::vector<std::string> fields = {r.set_name,
                                           number_text(r.run_index),
                                           number_text(r.seed),
                                           number_text(r.drones),
                                           number_text(r.d_int_m),
                                           number_text(r.speed_mps),
                                           r.sensor_function,
                                           r.mode,
                                           r.ok ? "1" : "0",
                                           r.failure_reason,
                                           number_text(r.task_time_s),
                                           number_text(r.wall_time_s),
                                           number_text(r.collisions_obstacle),
                                           number_text(r.collisions_drone),
                                           number_text(r.collisions_ground),
                                           number_text(r.min_inter_drone_m),
                                           number_text(r.min_clearance_m),
                                           encode_params(r.params),
                                           number_text(r.metrics.order_mean),
                                           number_text(r.metrics.order_min),
                                           number_text(r.metrics.speed_mean_mps),
                                           number_text(r.metrics.near_misses),
                                           number_text(r.metrics.components_max),
                                           number_text(r.metrics.lambda2_min),
                                           number_text(r.metrics.range_m),
                                           number_text(r.metrics.near_miss_m)};
  std::string row;
  for (std::size_t i = 0; i < fields.size(); ++i) row += (i ? "," : "") + csv_field(fields[i]);
  return row + "\n";
}

/// Closes a file descriptor on every path out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

void write_all(int fd, const std::string& data, const std::string& path) {
  std::size_t done = 0;
  while (done < data.size()) {
    ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw io_error(path, "write failed", errno);
    }
    done += static_cast<std::size_t>(n);
  }
}

// ---- CSV reading ----

struct CsvRecord {
  int line;  ///< line where the record starts
  std::vector<std::string> fields;
};

std::vector<CsvRecord> parse_csv(const std::string& text, const std::string& path) {
  std::vector<CsvRecord> out;
  CsvRecord rec{1, {}};
  std::string field;
  bool in_quotes = false, was_quoted = false;
  int line = 1;
  auto fail = [&](const std::string& why) {
    throw std::runtime_error(path + ":" + std::to_string(line) + ": " + why);
  };
  auto end_record = [&] {
    rec.fields.push_back(std::move(field));
    field.clear();
    // A blank line is not a record.
    if (!(rec.fields.size() == 1 && rec.fields[0].empty() && !was_quoted))
      out.push_back(std::move(rec));
    rec = CsvRecord{line + 1, {}};
    was_quoted = false;
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_quotes) {
      if (c == '"') {
        if (i + 1 < text.size() && text[i + 1] == '"') {
          field += '"';
          ++i;
        } else {
          in_quotes = false;
          if (i + 1 < text.size() && text[i + 1] != ',' && text[i + 1] != '\n' &&
              text[i + 1] != '\r')
            fail("text after a closing quote");
        }
      } else {
        if (c == '\n') ++line;
        field += c;
      }
    } else if (c == '"') {
      if (!field.empty()) fail("quote inside an unquoted field");
      in_quotes = was_quoted = true;
    } else if (c == ',') {
      rec.fields.push_back(std::move(field));
      field.clear();
    } else if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') {
      continue;
    } else if (c == '\n') {
      end_record();
      ++line;
    } else {
      field += c;
    }
  }
  if (in_quotes) fail("unterminated quoted field");
  if (!field.empty() || !rec.fields.empty() || was_quoted) end_record();
  return out;
}

std::map<std::string, std::string> decode_params(const std::string& s,
                                                 const std::function<void(std::string)>& fail) {
  std::map<std::string, std::string> out;
  if (s.empty()) return out;
  std::string key, value, *cur = &key;
  bool has_eq = false;
  auto flush = [&] {
    if (!has_eq) fail("params: '" + key + "' has no '='");
    out[key] = value;
    key.clear();
    value.clear();
    cur = &key;
    has_eq = false;
  };
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (c == '\\' && i + 1 < s.size()) {
      *cur += s[++i];
    } else if (c == '=' && !has_eq) {
      has_eq = true;
      cur = &value;
    } else if (c == ';') {
      flush();
    } else {
      *cur += c;
    }
  }
  flush();
  return out;
}

// ---- statistics and formatting ----

std::string fixed(double v, int decimals, const char* unit = "") {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f%s", decimals, v, unit);
  return buf;
}

std::string shortest(double v, const char* unit = "") {
  if (!std::isfinite(v)) return "n/a";
  std::ostringstream os;
  os << v << unit;
  return os.str();
}

std::string md_cell(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += '\\';
    out += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return out;
}

/// Records grouped by set name, sets in order of first appearance.
std::vector<std::pair<std::string, std::vector<const RunRecord*>>> group_by_set(
    const std::vector<RunRecord>& records) {
  std::vector<std::pair<std::string, std::vector<const RunRecord*>>> sets;
  std::map<std::string, std::size_t> index;
  for (const auto& r : records) {
    auto [it, fresh] = index.emplace(r.set_name, sets.size());
    if (fresh) sets.emplace_back(r.set_name, std::vector<const RunRecord*>{});
    sets[it->second].second.push_back(&r);
  }
  return sets;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::trunc);
  out << text;
  out.flush();
  if (!out) throw io_error(path, "cannot write", errno);
}

/// Runs `gnuplot -e "cd 'dir'" script`, its output going to log; throws on failure.
void run_gnuplot(const std::string& dir, const std::string& script, const std::string& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  const std::string cd = "cd " + gnuplot_string(dir);
  std::vector<char*> argv = {const_cast<char*>("gnuplot"), const_cast<char*>("-e"),
                             const_cast<char*>(cd.c_str()), const_cast<char*>(script.c_str()),
                             nullptr};
  // Not the stop signals this process blocks for its own threads (install_stop_signals).
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  const int err = posix_spawnp(&pid, "gnuplot", &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (err == ENOENT)
    throw std::runtime_error("gnuplot not found on PATH; install it (apt-get install gnuplot-nox)");
  if (err != 0) throw io_error("gnuplot", "cannot start", err);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw io_error("gnuplot", "waitpid failed", errno);
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::string msg = read_text(log);
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    throw std::runtime_error("gnuplot failed on " + script + (msg.empty() ? "" : ": " + msg));
  }
}

/// The gnuplot commands of one set's plot (render_gnuplot() adds the terminals).
std::string plot_body(const std::string& stem, const SetSummary& s, int max_run) {
  std::ostringstream title;
  title << s.name << ": time to complete (" << s.drones << " drones, D_int "
        << shortest(s.d_int_m, " m") << ", " << shortest(s.speed_mps, " m/s") << ", "
        << s.sensor_function << ")";
  if (s.failures > 0) title << ", " << s.failures << " of " << s.runs << " runs failed";

  std::ostringstream gp;
  gp << "# Task time per run for " << s.name << " (written by ddswarm; run: gnuplot " << stem
     << ".gp)\n"
     << "# Data columns: run, task time s (NaN: failed), same for runs with collisions, "
        "collisions, ok\n"
     << "data = " << gnuplot_string(stem + ".dat") << "\n"
     << "set title " << gnuplot_string(title.str()) << "\n"
     << "set xlabel 'Run'\nset ylabel 'Time to complete [s]'\n"
     << "set xrange [0.5:" << max_run << ".5]\nset xtics 1\nset grid ytics\n"
     << "set key bottom right\n";
  if (std::isfinite(s.mean_time_s)) {
    gp << "mean = " << number_text(s.mean_time_s) << "\n"
       << "set yrange [0:*]\n"
       << "plot data using 1:2 with linespoints pt 7 lc rgb '#1f77b4' title 'task time', \\\n";
    if (s.mean_collisions > 0)
      gp << "     data using 1:3 with points pt 9 ps 1.8 lc rgb '#d62728' title 'run with "
            "collisions', \\\n";
    if (s.failures > 0)
      gp << "     data using 1:($5 == 0 ? 0 : 1/0) with points pt 2 ps 2 lc rgb 'black' "
            "title 'failed run', \\\n";
    gp << "     mean with lines dt 2 lc rgb '#555555' title sprintf('mean %.1f s', mean)\n";
  } else {
    gp << "set yrange [0:1]\nset label 1 'no successful runs' at graph 0.5, graph 0.5 center\n"
       << "plot 1/0 notitle\n";
  }
  return gp.str();
}

}  // namespace

void append_csv(const std::string& path, const RunRecord& record) {
  const std::string header = header_line() + "\n";
  const std::string row = csv_row(record);
  Fd f{::open(path.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0644)};
  if (f.fd < 0) throw io_error(path, "cannot open for appending", errno);
  if (::flock(f.fd, LOCK_EX) != 0) throw io_error(path, "cannot lock", errno);
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw io_error(path, "cannot stat", errno);

  std::string data;
  if (st.st_size == 0) {
    data = header + row;
  } else {
    std::string first(header.size(), '\0');
    const ssize_t n = ::pread(f.fd, first.data(), first.size(), 0);
    if (n < 0) throw io_error(path, "cannot read header", errno);
    first.resize(static_cast<std::size_t>(n));
    if (first != header)
      throw std::runtime_error(path + ": not a ddswarm run CSV of this version (header differs: '" +
                               first.substr(0, first.find('\n')) + "')");
    // A row cut short by a crash must not swallow ours.
    char last = '\n';
    if (::pread(f.fd, &last, 1, st.st_size - 1) != 1) throw io_error(path, "cannot read", errno);
    data = (last == '\n' ? "" : "\n") + row;
  }
  write_all(f.fd, data, path);
  if (::fsync(f.fd) != 0) throw io_error(path, "fsync failed", errno);
  const int fd = f.fd;
  f.fd = -1;
  if (::close(fd) != 0) throw io_error(path, "close failed", errno);
}

std::vector<RunRecord> read_csv(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw io_error(path, "cannot open", errno);
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw io_error(path, "read failed", errno);
  const auto records = parse_csv(ss.str(), path);
  if (records.empty()) throw std::runtime_error(path + ": empty file (no header)");

  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < records[0].fields.size(); ++i) col[records[0].fields[i]] = i;
  for (const auto& c : kColumns)
    if (!col.count(c)) throw std::runtime_error(path + ":1: missing column '" + c + "'");

  std::vector<RunRecord> out;
  for (std::size_t ri = 1; ri < records.size(); ++ri) {
    const CsvRecord& rec = records[ri];
    auto fail = [&](const std::string& why) {
      throw std::runtime_error(path + ":" + std::to_string(rec.line) + ": " + why);
    };
    if (rec.fields.size() != records[0].fields.size())
      fail("expected " + std::to_string(records[0].fields.size()) + " fields, found " +
           std::to_string(rec.fields.size()));
    auto text = [&](const char* name) -> const std::string& { return rec.fields[col.at(name)]; };
    auto number = [&](const char* name, auto& v) {
      const std::string& s = text(name);
      const char* b = s.data() + (!s.empty() && s.front() == '+');
      auto [end, ec] = std::from_chars(b, s.data() + s.size(), v);
      if (ec != std::errc() || end != s.data() + s.size() || s.empty())
        fail(std::string(name) + " = '" + s + "': not a number");
    };
    RunRecord r;
    r.set_name = text("set_name");
    number("run_index", r.run_index);
    number("seed", r.seed);
    number("drones", r.drones);
    number("d_int_m", r.d_int_m);
    number("speed_mps", r.speed_mps);
    r.sensor_function = text("sensor_function");
    r.mode = text("mode");
    const std::string& ok = text("ok");
    if (ok == "1" || ok == "true")
      r.ok = true;
    else if (ok == "0" || ok == "false")
      r.ok = false;
    else
      fail("ok = '" + ok + "': must be 1 or 0");
    r.failure_reason = text("failure_reason");
    number("task_time_s", r.task_time_s);
    number("wall_time_s", r.wall_time_s);
    number("collisions_obstacle", r.collisions_obstacle);
    number("collisions_drone", r.collisions_drone);
    number("collisions_ground", r.collisions_ground);
    number("min_inter_drone_m", r.min_inter_drone_m);
    number("min_clearance_m", r.min_clearance_m);
    r.params = decode_params(text("params"), fail);
    auto metric = [&](const char* name, auto& v) {
      if (col.count(name)) number(name, v);
    };
    metric("order_mean", r.metrics.order_mean);
    metric("order_min", r.metrics.order_min);
    metric("speed_mean_mps", r.metrics.speed_mean_mps);
    metric("near_misses", r.metrics.near_misses);
    metric("components_max", r.metrics.components_max);
    metric("lambda2_min", r.metrics.lambda2_min);
    metric("metrics_range_m", r.metrics.range_m);
    metric("near_miss_m", r.metrics.near_miss_m);
    out.push_back(std::move(r));
  }
  return out;
}

std::vector<SetSummary> summarize(const std::vector<RunRecord>& records) {
  std::vector<SetSummary> out;
  for (const auto& [name, runs] : group_by_set(records)) {
    SetSummary s;
    const RunRecord& first = *runs.front();
    s.name = name;
    s.drones = first.drones;
    s.d_int_m = first.d_int_m;
    s.speed_mps = first.speed_mps;
    s.sensor_function = first.sensor_function;
    s.mode = first.mode;
    s.runs = static_cast<int>(runs.size());
    s.min_inter_drone_m = kInf;
    s.min_clearance_m = kInf;
    s.min_time_s = kInf;
    s.max_time_s = -kInf;
    std::vector<double> times;
    double collisions = 0, obstacle = 0, drone = 0, ground = 0, wall = 0;
    double order_sum = 0, speed_sum = 0, near_sum = 0;
    int speed_runs = 0;
    s.min_order = s.min_lambda2 = kNaN;
    for (const RunRecord* r : runs) {
      if (r->drones != first.drones || r->d_int_m != first.d_int_m ||
          r->speed_mps != first.speed_mps || r->sensor_function != first.sensor_function ||
          r->mode != first.mode)
        s.consistent = false;
      if (!r->ok) ++s.failures;
      if (r->ok && std::isfinite(r->task_time_s)) {
        times.push_back(r->task_time_s);
        s.min_time_s = std::min(s.min_time_s, r->task_time_s);
        s.max_time_s = std::max(s.max_time_s, r->task_time_s);
      }
      collisions += r->collisions();
      obstacle += r->collisions_obstacle;
      drone += r->collisions_drone;
      ground += r->collisions_ground;
      wall += r->wall_time_s;
      // fmin ignores NaN (a run that did not measure it).
      s.min_inter_drone_m = std::fmin(s.min_inter_drone_m, r->min_inter_drone_m);
      s.min_clearance_m = std::fmin(s.min_clearance_m, r->min_clearance_m);
      const SwarmTaskMetrics& m = r->metrics;
      if (std::isfinite(m.order_mean)) {
        ++s.metrics_runs;
        order_sum += m.order_mean;
        near_sum += m.near_misses;
      }
      if (std::isfinite(m.speed_mean_mps)) {
        ++speed_runs;
        speed_sum += m.speed_mean_mps;
      }
      s.min_order = std::fmin(s.min_order, m.order_min);
      s.min_lambda2 = std::fmin(s.min_lambda2, m.lambda2_min);
      s.max_components = std::max(s.max_components, m.components_max);
    }
    s.mean_order = s.metrics_runs ? order_sum / s.metrics_runs : kNaN;
    s.mean_near_misses = s.metrics_runs ? near_sum / s.metrics_runs : kNaN;
    s.mean_speed_mps = speed_runs ? speed_sum / speed_runs : kNaN;
    s.successes = static_cast<int>(times.size());
    const double n = static_cast<double>(runs.size());
    s.mean_collisions = collisions / n;
    s.mean_collisions_obstacle = obstacle / n;
    s.mean_collisions_drone = drone / n;
    s.mean_collisions_ground = ground / n;
    s.mean_wall_time_s = wall / n;
    if (times.empty()) {
      s.mean_time_s = s.stddev_time_s = s.min_time_s = s.max_time_s = kNaN;
    } else {
      double sum = 0;
      for (double t : times) sum += t;
      s.mean_time_s = sum / static_cast<double>(times.size());
      if (times.size() < 2) {
        s.stddev_time_s = kNaN;
      } else {
        double sq = 0;
        for (double t : times) sq += (t - s.mean_time_s) * (t - s.mean_time_s);
        s.stddev_time_s = std::sqrt(sq / static_cast<double>(times.size() - 1));
      }
    }
    out.push_back(std::move(s));
  }
  return out;
}

namespace {
/// A Markdown table: one column per set, one row per (label, cell of a set).
std::string sets_table(
    const std::vector<SetSummary>& sets,
    const std::vector<std::pair<std::string, std::function<std::string(const SetSummary&)>>>&
        rows) {
  std::ostringstream os;
  os << "| |";
  for (const auto& s : sets) os << ' ' << md_cell(s.name) << " |";
  os << "\n|---|";
  for (std::size_t i = 0; i < sets.size(); ++i) os << "---|";
  os << '\n';
  for (const auto& [label, cell] : rows) {
    os << "| " << label << " |";
    for (const auto& s : sets) os << ' ' << cell(s) << " |";
    os << '\n';
  }
  return os.str();
}
}  // namespace

std::string markdown_table(const std::vector<SetSummary>& sets) {
  bool any_mixed = false;
  auto setting = [&](const SetSummary& s, std::string text) {
    if (!s.consistent) {
      any_mixed = true;
      text += "\\*";
    }
    return text;
  };
  using Cell = std::function<std::string(const SetSummary&)>;
  const std::vector<std::pair<std::string, Cell>> rows = {
      {"Drones nr", [&](const SetSummary& s) { return setting(s, std::to_string(s.drones)); }},
      {"Inter-distance", [&](const SetSummary& s) { return setting(s, shortest(s.d_int_m, "m")); }},
      {"Velocity", [&](const SetSummary& s) { return setting(s, shortest(s.speed_mps, "m/s")); }},
      {"Sensor Function",
       [&](const SetSummary& s) { return setting(s, md_cell(s.sensor_function)); }},
      {"Avg. task time", [](const SetSummary& s) { return fixed(s.mean_time_s, 1, "s"); }},
      {"Standard deviation", [](const SetSummary& s) { return fixed(s.stddev_time_s, 2, "s"); }},
      {"Avg. collisions", [](const SetSummary& s) { return fixed(s.mean_collisions, 2); }},
      {"Min. inter-drone distance",
       [](const SetSummary& s) { return fixed(s.min_inter_drone_m, 2, "m"); }},
      {"Failures", [](const SetSummary& s) {
         return std::to_string(s.failures) + "/" + std::to_string(s.runs);
       }}};

  std::ostringstream os;
  os << sets_table(sets, rows);
  if (any_mixed) os << "\n\\* runs of this set used different values; the first run's are shown.\n";
  return os.str();
}

std::string metrics_table(const std::vector<SetSummary>& sets) {
  if (std::none_of(sets.begin(), sets.end(),
                   [](const SetSummary& s) { return s.metrics_runs > 0; }))
    return "";
  using Cell = std::function<std::string(const SetSummary&)>;
  const std::vector<std::pair<std::string, Cell>> rows = {
      {"Avg. order", [](const SetSummary& s) { return fixed(s.mean_order, 3); }},
      {"Min. order", [](const SetSummary& s) { return fixed(s.min_order, 3); }},
      {"Avg. speed", [](const SetSummary& s) { return fixed(s.mean_speed_mps, 2, "m/s"); }},
      {"Avg. near misses", [](const SetSummary& s) { return fixed(s.mean_near_misses, 2); }},
      {"Max. components",
       [](const SetSummary& s) {
         return s.max_components > 0 ? std::to_string(s.max_components) : std::string("n/a");
       }},
      {"Min. algebraic connectivity", [](const SetSummary& s) { return fixed(s.min_lambda2, 2); }},
      {"Runs measured", [](const SetSummary& s) {
         return std::to_string(s.metrics_runs) + "/" + std::to_string(s.runs);
       }}};
  return sets_table(sets, rows);
}

std::string plot_stem(const std::string& set_name) {
  std::string stem;
  for (unsigned char c : set_name) {
    if (std::isalnum(c))
      stem += static_cast<char>(std::tolower(c));
    else if (!stem.empty() && stem.back() != '_')
      stem += '_';
  }
  while (!stem.empty() && stem.back() == '_') stem.pop_back();
  return stem.empty() ? "set" : stem;
}

std::vector<std::string> write_plots(const std::vector<RunRecord>& records,
                                     const std::string& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error(out_dir + ": cannot create directory: " + ec.message());
  const std::string dir = fs::absolute(out_dir).lexically_normal().string();

  const auto summaries = summarize(records);
  const auto groups = group_by_set(records);
  std::set<std::string> used;
  std::vector<std::string> pngs;
  for (std::size_t i = 0; i < groups.size(); ++i) {
    const auto& runs = groups[i].second;
    std::string stem = plot_stem(groups[i].first);
    for (int k = 2; used.count(stem); ++k)
      stem = plot_stem(groups[i].first) + "_" + std::to_string(k);
    used.insert(stem);

    std::ostringstream dat;
    dat << "# " << groups[i].first
        << "\n# run task_time_s task_time_s_with_collisions collisions ok\n";
    int max_run = 1;
    for (const RunRecord* r : runs) {
      const bool shown = r->ok && std::isfinite(r->task_time_s);
      const std::string t = shown ? number_text(r->task_time_s) : "NaN";
      dat << r->run_index + 1 << ' ' << t << ' ' << (shown && r->collisions() > 0 ? t : "NaN")
          << ' ' << r->collisions() << ' ' << (r->ok ? 1 : 0) << '\n';
      max_run = std::max(max_run, r->run_index + 1);
    }
    write_text(dir + "/" + stem + ".dat", dat.str());
    pngs.push_back(render_gnuplot(dir, stem, plot_body(stem, summaries[i], max_run), 800, 500));
  }
  // The summary needs a mean to draw: with every run failed, gnuplot finds no point at all.
  const bool any_mean = std::any_of(summaries.begin(), summaries.end(), [](const SetSummary& s) {
    return std::isfinite(s.mean_time_s);
  });
  if (summaries.size() > 1 && any_mean) pngs.push_back(write_summary_plot(summaries, dir));
  if (std::any_of(summaries.begin(), summaries.end(),
                  [](const SetSummary& s) { return s.metrics_runs > 0; }))
    pngs.push_back(write_metrics_plot(summaries, dir));
  return pngs;
}

std::string write_summary_plot(const std::vector<SetSummary>& sets, const std::string& dir) {
  // One bar per set: mean task time with its standard deviation, so a sweep
  // reads at a glance; the failure count sits on top of a set that had any.
  std::ostringstream dat;
  dat << "# index mean_s stddev_s failures name\n";
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const auto& s = sets[i];
    dat << i << ' ' << (std::isfinite(s.mean_time_s) ? number_text(s.mean_time_s) : "NaN") << ' '
        << (std::isfinite(s.stddev_time_s) ? number_text(s.stddev_time_s) : "0") << ' '
        << s.failures << " \"";
    for (char c : s.name) dat << (c == '"' ? '\'' : c);  // data columns quote with "
    dat << "\"\n";
  }
  const std::string base = dir + "/summary";
  write_text(base + ".dat", dat.str());
  std::ostringstream gp;
  gp << "data = " << gnuplot_string("summary.dat") << "\n"  // gnuplot runs in dir
     << "set title 'Task time per set (mean and standard deviation)'\n"
     << "set ylabel 'Time to complete [s]'\nset yrange [0:*]\nset grid ytics\n"
     << "set style fill solid 0.6 border -1\nset boxwidth 0.6\nset xtics rotate by -30\n"
     << "set xrange [-0.6:" << sets.size() - 0.4 << "]\nunset key\n"
     << "plot data using 1:2:xtic(5) with boxes lc rgb '#1f77b4', \\\n"
     << "     data using 1:2:3 with yerrorbars pt 0 lc rgb 'black', \\\n"
     << "     data using 1:($4 > 0 ? $2 : 1/0):(sprintf('%d failed', $4)) with labels offset "
        "0,1.2\n";
  return render_gnuplot(dir, "summary", gp.str(), 900, 500);
}

std::string write_metrics_plot(const std::vector<SetSummary>& sets, const std::string& dir) {
  // Two bars per set: the order the law kept (left axis; higher is more
  // aligned) beside how close the drones came (right axis, the near misses
  // written above), so that one law's alignment is weighed against its
  // safety. One plot, not a multiplot: render_gnuplot replots it as SVG.
  auto num = [](double v) { return std::isfinite(v) ? number_text(v) : std::string("NaN"); };
  std::ostringstream dat;
  dat << "# index mean_order min_order min_inter_drone_m mean_near_misses name\n";
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const auto& s = sets[i];
    dat << i << ' ' << num(s.mean_order) << ' ' << num(s.min_order) << ' '
        << num(s.min_inter_drone_m) << ' ' << num(s.mean_near_misses) << " \"";
    for (char c : s.name) dat << (c == '"' ? '\'' : c);  // data columns quote with "
    dat << "\"\n";
  }
  write_text(dir + "/metrics.dat", dat.str());
  // Room above the tallest distance bar for its label; the legend goes under
  // the plot, clear of every bar.
  double top_m = 0.1;
  for (const auto& s : sets)
    if (std::isfinite(s.min_inter_drone_m)) top_m = std::max(top_m, s.min_inter_drone_m);
  std::ostringstream gp;
  gp << "data = " << gnuplot_string("metrics.dat") << "\n"  // gnuplot runs in dir
     << "set title 'Swarm metrics per set: order and closest approach'\n"
     << "set style fill solid 0.6 border -1\nset boxwidth 0.35\nset grid ytics\n"
     << "set xrange [-0.6:" << sets.size() - 0.4 << "]\nset xtics rotate by -30\n"
     << "set ylabel 'Order (velocity correlation)'\nset yrange [-1:1.15]\n"
     << "set y2label 'Min. inter-drone distance [m]'\nset y2range [0:" << number_text(1.2 * top_m)
     << "]\nset y2tics\n"
     << "set ytics nomirror\nset key below horizontal\n"
     << "plot data using 1:(1/0):xtic(6) notitle, \\\n"  // the set's name under its pair
     << "     data using ($1-0.2):2 with boxes lc rgb '#2ca02c' title 'order, mean of the runs', "
        "\\\n"
     << "     data using ($1-0.2):3 with points pt 7 ps 1.4 lc rgb 'black' title 'order, lowest "
        "tick', \\\n"
     << "     data using ($1+0.2):4 axes x1y2 with boxes lc rgb '#1f77b4' title 'min. "
        "inter-drone distance', \\\n"
     << "     data using ($1+0.2):4:(sprintf('%.1f near misses/run', $5)) axes x1y2 with labels "
        "offset 0,0.8 notitle\n";
  return render_gnuplot(dir, "metrics", gp.str(), 900, 500);
}

std::string gnuplot_string(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += '\'';
    out += (c == '\n' || c == '\r') ? ' ' : c;
  }
  return out + "'";
}

std::string render_gnuplot(const std::string& dir, const std::string& stem, const std::string& plot,
                           int width, int height) {
  // gnuplot runs in dir: the script is named by its absolute path, its outputs relative to dir.
  const std::string base = fs::absolute(dir).string() + "/" + stem;
  const std::string size = std::to_string(width) + "," + std::to_string(height);
  std::ostringstream script;
  script << "if (strstrt(GPVAL_TERMINALS, ' pngcairo ') > 0) {\n"
         << "  set terminal pngcairo size " << size << " noenhanced font 'sans,10'\n"
         << "} else {\n  set terminal png size " << size << " noenhanced\n}\n"
         << "set output " << gnuplot_string(stem + ".png") << "\n"
         << plot << "set terminal svg size " << size << " noenhanced\n"
         << "set output " << gnuplot_string(stem + ".svg") << "\nreplot\nunset output\n";
  write_text(base + ".gp", script.str());
  std::error_code rm;
  fs::remove(base + ".png", rm);  // an old plot must not pass for this one
  fs::remove(base + ".svg", rm);
  run_gnuplot(dir, base + ".gp", base + ".log");
  for (const char* ext : {".png", ".svg"}) {
    if (fs::file_size(base + ext, rm) == 0 || rm)
      throw std::runtime_error(base + ext + ": gnuplot wrote no plot (see " + base + ".log)");
  }
  fs::remove(base + ".log", rm);
  return base + ".png";
}

}  // namespace ddswarm::gs
