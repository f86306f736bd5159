#include "ground_station/web/web_bridge.hpp"

#include <fmt/format.h>

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "common/participant.hpp"
#include "common/process.hpp"
#include "ground_station/dds_commander.hpp"
#include "ground_station/web/web_frame.hpp"
#include "ground_station/web/web_recording.hpp"

namespace ddswarm::gs::web {

namespace {

constexpr double kStatusPeriodS = 0.5;       // status and running-task updates: 2 Hz
constexpr double kReplayInfoPeriodS = 0.25;  // `replay` while playing: 4 Hz
constexpr double kCollisionsPerS = 50;       // per client
constexpr double kMessagesPerS = 50;         // client messages per client
constexpr std::size_t kCollisionRing = 1024;
constexpr std::size_t kMaxPendingCommands = 8;
constexpr std::size_t kMaxRecordings = 4;

using Text = std::shared_ptr<const std::string>;
Text text(std::string s) { return std::make_shared<const std::string>(std::move(s)); }

/// A token bucket: `rate` per second, bursts of `rate`.
struct Bucket {
  double rate, tokens, wall;
  explicit Bucket(double r) : rate(r), tokens(r), wall(wall_seconds()) {}
  bool take() {
    const double now = wall_seconds();
    tokens = std::min(rate, tokens + (now - wall) * rate);
    wall = now;
    if (tokens < 1) return false;
    tokens -= 1;
    return true;
  }
};

/// Index of the first element with t > x.
template <class V>
std::size_t after(const V& v, double x) {
  auto it =
      std::upper_bound(v.begin(), v.end(), x, [](double a, const auto& e) { return a < e.t; });
  return static_cast<std::size_t>(it - v.begin());
}

}  // namespace

std::string WebBridgeCounts::line() const {
  return fmt::format(
      "web: {} client(s), {} frames sent, {} replaced for slow clients, {} malformed messages, {} "
      "rate-limited, "
      "{} commands, {} recordings",
      clients, frames_sent, frames_replaced, malformed, rate_limited, commands, uploads);
}

struct WebBridge::Impl {
  WebBridgeOptions opt;
  std::atomic<bool> stopping{false};  // stop()

  // ---- written by DDS callbacks (pointer swaps under a short lock) ----
  struct Latest {
    std::mutex mu;
    std::shared_ptr<const msg::SwarmState> state;
    std::shared_ptr<const msg::Scene> scene;
    std::shared_ptr<const msg::SimStatus> status;
    std::shared_ptr<const msg::TaskStatus> task;
    std::uint64_t scene_ver = 0, status_ver = 0, task_ver = 0;
    std::deque<msg::CollisionEvent> collisions;  // the last kCollisionRing
    std::uint64_t collision_seq = 0;             // events ever received
  } latest;

  std::unique_ptr<DdsCommander> commander;
  MeshFiles meshes;  // before the server, whose thread asks it for files
  std::unique_ptr<WebServer> server;

  // ---- the server's thread only ----
  struct Client {
    std::shared_ptr<WebClient> peer;
    bool rays = false;
    Bucket incoming{kMessagesPerS};
    double last_rate_error = -1e9;
    std::uint64_t rate_dropped = 0;
    Bucket collisions{kCollisionsPerS};
    std::uint64_t collisions_dropped = 0;
    // live
    const msg::SwarmState* last_state = nullptr;
    std::uint64_t scene_sent = 0, status_sent = 0, task_sent = 0, collision_seen = 0;
    double status_wall = -1e9, task_wall = -1e9;
    int task_phase_sent = -1;
    // replay
    std::shared_ptr<const Recording> rec;
    double rt = 0, rate = 1, last_wall = 0, info_wall = -1e9;
    bool playing = false;
    std::size_t frame_sent = SIZE_MAX, status_idx = 0, status_sent_idx = SIZE_MAX, task_idx = 0,
                task_sent_idx = SIZE_MAX, collision_idx = 0;
  };
  std::map<std::uint64_t, Client> clients;
  std::map<std::string, std::shared_ptr<const Recording>> recordings;
  std::deque<std::string> recording_order;
  std::uint64_t next_recording = 1;
  struct Cache {
    const msg::SwarmState* key = nullptr;
    std::shared_ptr<const msg::SwarmState> hold;
    Frame frame;
    Text plain, with_rays;
    std::uint64_t scene_ver = 0, scene_content = 0, status_ver = 0, task_ver = 0;
    Text scene, status, task;
    int task_phase = -1;
  } cache;

  // ---- counters (read at the end) ----
  struct {
    std::atomic<std::uint64_t> clients{0}, frames_sent{0}, frames_replaced{0}, malformed{0},
        rate_limited{0}, commands{0}, uploads{0};
  } n;

  // ---- the command worker ----
  struct Job {
    std::weak_ptr<WebClient> peer;
    CommandRequest req;
  };
  std::mutex jobs_mu;
  std::condition_variable jobs_cv;
  std::deque<Job> jobs;
  bool quit = false;
  std::thread worker;
  std::thread loader;

  Participant dds;  // last member: closed first in ~Impl, before what its callbacks touch

  explicit Impl(const WebBridgeOptions& o)
      : opt(o), meshes(o.mesh_dir), dds(o.dds, "ddswarm-gs-web") {
    opt.gs.validate();
    opt.task.validate();
    commander = std::make_unique<DdsCommander>(opt.gs, opt.dds);
    WebHooks hooks;
    hooks.on_open = [this](const std::shared_ptr<WebClient>& p) { on_open(p); };
    hooks.on_close = [this](const std::shared_ptr<WebClient>& p) { on_close(p); };
    hooks.on_tick = [this](const std::shared_ptr<WebClient>& p) { on_tick(p); };
    hooks.on_message = [this](const std::shared_ptr<WebClient>& p, std::string_view t,
                              bool binary) { on_message(p, t, binary); };
    hooks.on_upload = [this](const std::filesystem::path& f, const std::string& name,
                             std::function<void(int, std::string)> respond) {
      on_upload(f, name, std::move(respond));
    };
    hooks.on_mesh = [this](std::string_view path) { return meshes.find(path); };
    server = std::make_unique<WebServer>(opt.server, std::move(hooks));
    subscribe();
    worker = std::thread([this] { work(); });
  }

  ~Impl() {
    dds.close();
    {
      std::lock_guard<std::mutex> lock(jobs_mu);
      quit = true;
    }
    jobs_cv.notify_all();
    if (worker.joinable()) worker.join();
    if (loader.joinable()) loader.join();
    clients.clear();
  }

  void subscribe() {
    dds.reader<msg::SwarmState>([this](const msg::SwarmState& s, const fdds::SampleInfo&) {
      auto p = std::make_shared<const msg::SwarmState>(s);
      std::lock_guard<std::mutex> lock(latest.mu);
      latest.state.swap(p);
    });
    dds.reader<msg::Scene>([this](const msg::Scene& s, const fdds::SampleInfo&) {
      auto p = std::make_shared<const msg::Scene>(s);
      std::lock_guard<std::mutex> lock(latest.mu);
      latest.scene.swap(p);
      ++latest.scene_ver;
    });
    dds.reader<msg::SimStatus>([this](const msg::SimStatus& s, const fdds::SampleInfo&) {
      auto p = std::make_shared<const msg::SimStatus>(s);
      std::lock_guard<std::mutex> lock(latest.mu);
      latest.status.swap(p);
      ++latest.status_ver;
    });
    dds.reader<msg::TaskStatus>([this](const msg::TaskStatus& s, const fdds::SampleInfo&) {
      auto p = std::make_shared<const msg::TaskStatus>(s);
      std::lock_guard<std::mutex> lock(latest.mu);
      latest.task.swap(p);
      ++latest.task_ver;
    });
    dds.reader<msg::CollisionEvent>([this](const msg::CollisionEvent& e, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(latest.mu);
      latest.collisions.push_back(e);
      if (latest.collisions.size() > kCollisionRing) latest.collisions.pop_front();
      ++latest.collision_seq;
    });
  }

  // ---- clients ----

  void on_open(const std::shared_ptr<WebClient>& p) {
    ++n.clients;
    auto& c = clients[p->id()];
    c.peer = p;
    {
      std::lock_guard<std::mutex> lock(latest.mu);
      c.collision_seen = latest.collision_seq;  // a new page starts from now
    }
    std::fprintf(stderr, "web: client %llu (%s) connected\n",
                 static_cast<unsigned long long>(p->id()), p->remote().c_str());
    p->send(text(encode_hello("live", opt.gs.name)));
    on_tick(p);  // scene, status and task at once
  }

  void on_close(const std::shared_ptr<WebClient>& p) {
    std::fprintf(stderr, "web: client %llu disconnected\n",
                 static_cast<unsigned long long>(p->id()));
    clients.erase(p->id());
  }

  void send_error(Client& c, const std::string& message,
                  std::optional<std::int64_t> id = std::nullopt) {
    ++n.malformed;
    c.peer->send(text(encode_error(message, id)));
  }

  void on_message(const std::shared_ptr<WebClient>& p, std::string_view t, bool binary) {
    auto it = clients.find(p->id());
    if (it == clients.end()) return;
    Client& c = it->second;
    if (!c.incoming.take()) {
      ++n.rate_limited;
      ++c.rate_dropped;
      const double now = wall_seconds();
      if (now - c.last_rate_error >= 1.0) {
        c.last_rate_error = now;
        p->send(text(encode_error(fmt::format("over {} messages per second: {} dropped so far",
                                              static_cast<int>(kMessagesPerS), c.rate_dropped))));
      }
      return;
    }
    if (binary)
      return send_error(
          c,
          fmt::format("binary frame of {} bytes: only JSON text messages are accepted", t.size()));
    auto parsed = parse_client_message(t);
    if (!parsed.request) return send_error(c, parsed.error, parsed.id);
    std::visit([&](auto& r) { handle(c, r); }, *parsed.request);
  }

  void handle(Client& c, const SubscribeRequest& r) {
    c.rays = r.rays;
    c.peer->set_tick_hz(r.fps);
  }

  void handle(Client& c, const CommandRequest& r) {
    if (c.rec) {
      c.peer->send(
          text(encode_ack(r.id, to_string(r.kind), false,
                          "this page is playing a recording; go live to command the swarm")));
      return;
    }
    std::unique_lock<std::mutex> lock(jobs_mu);
    if (jobs.size() >= kMaxPendingCommands) {
      lock.unlock();
      c.peer->send(
          text(encode_ack(r.id, to_string(r.kind), false,
                          fmt::format("busy: {} commands are waiting", kMaxPendingCommands))));
      return;
    }
    jobs.push_back({c.peer, r});
    jobs_cv.notify_one();
  }

  void handle(Client& c, const OpenRequest& r) {
    auto it = recordings.find(r.recording);
    if (it == recordings.end())
      return send_error(
          c,
          fmt::format("open.recording = \"{}\": no such recording (upload it first)", r.recording));
    c.rec = it->second;
    c.rt = c.rec->start();
    c.rate = 1;
    c.playing = true;
    c.last_wall = wall_seconds();
    seek(c);
    c.peer->send(text(encode_hello("replay", opt.gs.name)));
    if (c.rec->scene) c.peer->send(text(encode_scene(*c.rec->scene, meshes.offer(*c.rec->scene))));
    send_replay_info(c);
    on_tick(c.peer);
  }

  void handle(Client& c, const LiveRequest&) {
    c.rec.reset();
    c.last_state = nullptr;
    c.scene_sent = c.status_sent = c.task_sent = 0;
    c.task_phase_sent = -1;
    {
      std::lock_guard<std::mutex> lock(latest.mu);
      c.collision_seen = latest.collision_seq;
    }
    c.peer->send(text(encode_hello("live", opt.gs.name)));
    on_tick(c.peer);
  }

  void handle(Client& c, const ReplayRequest& r) {
    if (!c.rec)
      return send_error(c, "replay: this page is not playing a recording (open one first)");
    advance(c);
    const double end = c.rec->start() + c.rec->duration();
    switch (r.action) {
      case ReplayRequest::Action::kPlay:
        if (c.rt >= end) {
          c.rt = c.rec->start();
          seek(c);
        }
        c.playing = true;
        break;
      case ReplayRequest::Action::kPause:
        c.playing = false;
        break;
      case ReplayRequest::Action::kSeek:
        c.rt = std::clamp(r.t_s, c.rec->start(), end);
        seek(c);
        break;
      case ReplayRequest::Action::kRate:
        c.rate = r.rate;
        break;
    }
    send_replay_info(c);
    on_tick(c.peer);
  }

  // ---- pacing ----

  void on_tick(const std::shared_ptr<WebClient>& p) {
    auto it = clients.find(p->id());
    if (it == clients.end()) return;
    if (it->second.rec)
      replay_tick(it->second);
    else
      live_tick(it->second);
  }

  void offer(Client& c, Text frame) {
    ++n.frames_sent;
    if (!c.peer->offer_frame(std::move(frame))) ++n.frames_replaced;
  }

  void live_tick(Client& c) {
    std::shared_ptr<const msg::SwarmState> state;
    std::vector<msg::CollisionEvent> events;
    std::uint64_t skipped = 0;
    std::shared_ptr<const msg::Scene> new_scene;
    {
      std::lock_guard<std::mutex> lock(latest.mu);
      state = latest.state;
      if (latest.scene_ver != cache.scene_ver) {
        cache.scene_ver = latest.scene_ver;
        new_scene = latest.scene;
      }
      if (latest.status_ver != cache.status_ver) {
        cache.status_ver = latest.status_ver;
        cache.status = text(encode_status(*latest.status));
      }
      if (latest.task_ver != cache.task_ver) {
        cache.task_ver = latest.task_ver;
        cache.task = text(encode_task(*latest.task));
        cache.task_phase = latest.task->phase();
      }
      const std::uint64_t first = latest.collision_seq - latest.collisions.size();
      if (c.collision_seen < first) {
        skipped = first - c.collision_seen;
        c.collision_seen = first;
      }
      for (std::uint64_t s = c.collision_seen; s < latest.collision_seq; ++s)
        events.push_back(latest.collisions[s - first]);
      c.collision_seen = latest.collision_seq;
    }
    // Outside the lock the DDS callbacks take: offer() may read mesh files.
    if (new_scene) {
      auto s = text(encode_scene(*new_scene, meshes.offer(*new_scene)));
      if (!cache.scene || *cache.scene != *s) {
        cache.scene = s;
        ++cache.scene_content;
      }
    }

    const double now = wall_seconds();
    if (cache.scene && c.scene_sent != cache.scene_content) {
      c.scene_sent = cache.scene_content;
      c.peer->send(cache.scene);
    }
    if (cache.status && c.status_sent != cache.status_ver &&
        now - c.status_wall >= kStatusPeriodS) {
      c.status_sent = cache.status_ver;
      c.status_wall = now;
      c.peer->send(cache.status);
    }
    if (cache.task && c.task_sent != cache.task_ver &&
        (cache.task_phase != c.task_phase_sent || now - c.task_wall >= kStatusPeriodS)) {
      c.task_sent = cache.task_ver;
      c.task_wall = now;
      c.task_phase_sent = cache.task_phase;
      c.peer->send(cache.task);
    }
    c.collisions_dropped += skipped;
    for (const auto& e : events) send_collision(c, e);
    if (state && state.get() != c.last_state) {
      c.last_state = state.get();
      offer(c, encoded(state, c.rays));
    }
  }

  /// The frame for this sample, encoded once for every client.
  Text encoded(const std::shared_ptr<const msg::SwarmState>& state, bool rays) {
    if (cache.key != state.get()) {
      cache.key = state.get();
      cache.hold = state;
      cache.frame = to_frame(*state);
      cache.plain.reset();
      cache.with_rays.reset();
    }
    Text& slot = rays ? cache.with_rays : cache.plain;
    if (!slot) slot = text(encode_frame(cache.frame, rays));
    return slot;
  }

  void send_collision(Client& c, const msg::CollisionEvent& e) {
    if (!c.collisions.take()) {
      ++c.collisions_dropped;
      return;
    }
    c.peer->send(text(encode_collision(e, c.collisions_dropped)));
  }

  // ---- replay ----

  /// Moves the replay clock on by the wall time since the last call.
  void advance(Client& c) {
    const double now = wall_seconds();
    if (c.playing) {
      c.rt += (now - c.last_wall) * c.rate;
      const double end = c.rec->start() + c.rec->duration();
      if (c.rt >= end) {
        c.rt = end;
        c.playing = false;
        send_replay_info(c);
      }
    }
    c.last_wall = now;
  }

  /// After a jump: the samples in force at rt, no flood of the events skipped.
  void seek(Client& c) {
    c.frame_sent = SIZE_MAX;
    c.status_idx = after(c.rec->status, c.rt);
    c.status_sent_idx = SIZE_MAX;
    c.task_idx = after(c.rec->tasks, c.rt);
    c.task_sent_idx = SIZE_MAX;
    c.collision_idx = after(c.rec->collisions, c.rt);
  }

  void send_replay_info(Client& c) {
    ReplayInfo info;
    info.name = c.rec->name;
    info.start_s = c.rec->start();
    info.duration_s = c.rec->duration();
    info.t_s = c.rt;
    info.playing = c.playing;
    info.rate = c.rate;
    info.frames = c.rec->frames.size();
    c.info_wall = wall_seconds();
    c.peer->send(text(encode_replay(info)));
  }

  void replay_tick(Client& c) {
    advance(c);
    const Recording& r = *c.rec;
    const double now = wall_seconds();
    while (c.status_idx < r.status.size() && r.status[c.status_idx].t <= c.rt) ++c.status_idx;
    if (c.status_idx > 0 && c.status_sent_idx != c.status_idx &&
        now - c.status_wall >= kStatusPeriodS) {
      c.status_sent_idx = c.status_idx;
      c.status_wall = now;
      c.peer->send(text(encode_status(r.status[c.status_idx - 1].sample)));
    }
    while (c.task_idx < r.tasks.size() && r.tasks[c.task_idx].t <= c.rt) ++c.task_idx;
    if (c.task_idx > 0 && c.task_sent_idx != c.task_idx) {
      const auto& t = r.tasks[c.task_idx - 1].sample;
      if (t.phase() != c.task_phase_sent || now - c.task_wall >= kStatusPeriodS) {
        c.task_sent_idx = c.task_idx;
        c.task_wall = now;
        c.task_phase_sent = t.phase();
        c.peer->send(text(encode_task(t)));
      }
    }
    while (c.collision_idx < r.collisions.size() && r.collisions[c.collision_idx].t <= c.rt)
      send_collision(c, r.collisions[c.collision_idx++].sample);
    const std::size_t idx = r.frame_at(c.rt);
    if (idx != c.frame_sent) {
      c.frame_sent = idx;
      offer(c, text(encode_frame(r.frames[idx], c.rays)));
    }
    if (c.playing && now - c.info_wall >= kReplayInfoPeriodS) send_replay_info(c);
  }

  // ---- uploads ----

  void on_upload(const std::filesystem::path& file, const std::string& name,
                 std::function<void(int, std::string)> respond) {
    if (loader.joinable()) loader.join();  // the previous one has answered (one upload at a time)
    const std::string id = fmt::format("r{}", next_recording++);
    loader = std::thread([this, file, name, id, respond = std::move(respond)] {
      std::shared_ptr<Recording> rec;
      try {
        rec = load_recording(file.string(), name);
      } catch (const std::exception& e) {
        std::string why = e.what();  // name the upload, not our temporary file
        for (auto p = why.find(file.string()); p != std::string::npos; p = why.find(file.string()))
          why.replace(p, file.string().size(), name);
        respond(400, nlohmann::json({{"error", why}})
                         .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
        return;
      }
      rec->id = id;
      server->post([this, rec, respond] {
        ++n.uploads;
        recordings[rec->id] = rec;
        recording_order.push_back(rec->id);
        while (recording_order.size() > kMaxRecordings) {  // pages playing one keep their copy
          recordings.erase(recording_order.front());
          recording_order.pop_front();
        }
        std::fprintf(stderr, "web: recording %s (%s): %zu frames, %.1f s\n", rec->id.c_str(),
                     rec->name.c_str(), rec->frames.size(), rec->duration());
        respond(200, nlohmann::json({{"id", rec->id},
                                     {"name", rec->name},
                                     {"duration", rec->duration()},
                                     {"start", rec->start()},
                                     {"frames", rec->frames.size()}})
                         .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
      });
    });
  }

  // ---- commands ----

  void work() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(jobs_mu);
        jobs_cv.wait(lock, [&] { return quit || !jobs.empty(); });
        if (quit) return;
        job = std::move(jobs.front());
        jobs.pop_front();
      }
      ++n.commands;
      CommandResult r = run_command(job.req);
      auto ack = text(encode_ack(job.req.id, to_string(job.req.kind), r.ok, r.message));
      server->post([peer = job.peer, ack] {
        if (auto p = peer.lock()) p->send(ack);
      });
    }
  }

  CommandResult run_command(const CommandRequest& r) {
    try {
      if (!commander->wait_for_server(opt.gs.discovery_timeout_s))
        return {false, stop_requested() ? "stopping"
                                        : fmt::format("no simulation server found on domain {}",
                                                      opt.dds.domain_id)};
      switch (r.kind) {
        case CommandKind::kTakeoff:
          return commander->takeoff(r.altitude_m);
        case CommandKind::kMove:
          return commander->move(r.v, r.duration_s);
        case CommandKind::kDistance:
          return commander->set_distance(r.value_m);
        case CommandKind::kLand:
          return commander->land();
        case CommandKind::kHold:
          return commander->hold();
        case CommandKind::kTask:
          return commander->task(r.speed_mps > 0 ? r.speed_mps : opt.task.speed_mps,
                                 r.epsilon_m > 0 ? r.epsilon_m : opt.task.epsilon_m);
        case CommandKind::kFollow:
          return commander->follow_leader(r.leader);
        case CommandKind::kTeleop:
          return commander->teleop(r.v);
      }
      return {false, "unknown command"};
    } catch (const std::exception& e) {
      return {false, e.what()};
    }
  }
};

WebBridge::WebBridge(const WebBridgeOptions& options) : impl_(std::make_unique<Impl>(options)) {}
WebBridge::~WebBridge() = default;

std::string WebBridge::url() const { return impl_->server->url(); }
void WebBridge::stop() { impl_->stopping = true; }

WebBridgeCounts WebBridge::run() {
  const double end = impl_->opt.duration_s > 0 ? wall_seconds() + impl_->opt.duration_s : 1e300;
  impl_->server->run([&] {
    if (wall_seconds() >= end) request_stop();  // also ends the commander's waits
    return stop_requested() || impl_->stopping;
  });
  auto& n = impl_->n;
  return {n.clients,      n.frames_sent, n.frames_replaced, n.malformed,
          n.rate_limited, n.commands,    n.uploads};
}

}  // namespace ddswarm::gs::web
