// The ground station starts a mission only when the server hears every agent:
// under load, discovery can match an agent with the ground station seconds
// before it matches the server, and the server releases a command only to
// the agents it hears (otherwise a run fails with "takeoff 5/6
// acknowledged; no ack from drones 0").
#include "ground_station/dds_commander.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "common/participant.hpp"
#include "common/process.hpp"
#include "experiment/experiment.hpp"

namespace ddswarm::gs {
namespace {

/// A random DDS domain in 80-99 for one test. ctest runs unit tests two at a
/// time; participant_test draws from 20-79 and shm_clean_test from 170-219,
/// so these never share a domain with them (multi-process tests run alone).
int random_test_domain() { return 90 + static_cast<int>(random_instance() % 5); }

/// Stands in for a server and six agents in one participant: heartbeats for
/// every drone, a SimStatus listing only `server_hears` of them.
class FakeSwarm {
 public:
  explicit FakeSwarm(const DdsConfig& cfg)
      : dds_(cfg, "fake_swarm"),
        w_status_(dds_.writer<msg::SimStatus>()),
        w_agent_(dds_.writer<msg::AgentStatus>()),
        w_ack_(dds_.writer<msg::MissionAck>()) {
    // w_ack_ and this reader only match the ground station's ack reader and
    // mission writer, which wait_for_swarm also waits for.
    dds_.reader<msg::MissionCommand>([](const msg::MissionCommand&, const fdds::SampleInfo&) {});
    thread_ = std::thread([this] {
      while (!stop_) {
        publish();
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
  }
  ~FakeSwarm() {
    stop_ = true;
    thread_.join();
  }
  void server_hears(int n) { server_hears_ = n; }
  /// Heartbeats only from drones first..5 (those below: not yet met, or dead).
  void heartbeats_from(int first) { heartbeats_from_ = first; }

 private:
  void publish() {
    msg::SimStatus s;
    s.mode(msg::MODE_LOCKSTEP);
    s.num_drones(kDrones);
    for (int i = 0; i < kDrones; ++i)
      if (i >= kDrones - server_hears_) s.live_agents().push_back(static_cast<std::uint16_t>(i));
    s.agents_live(static_cast<std::uint16_t>(s.live_agents().size()));
    w_status_.write(s);
    for (int i = heartbeats_from_; i < kDrones; ++i) {
      msg::AgentStatus a;
      a.drone_id(static_cast<std::uint16_t>(i));
      a.law(i >= 3 ? "reynolds" : "thesis");
      a.host("fake");
      a.pid(static_cast<std::uint32_t>(::getpid()));  // one process: one ack writer to match
      w_agent_.write(a);
    }
  }

  static constexpr int kDrones = 6;
  Participant dds_;
  Writer<msg::SimStatus> w_status_;
  Writer<msg::AgentStatus> w_agent_;
  Writer<msg::MissionAck> w_ack_;
  std::atomic<int> server_hears_{0};
  std::atomic<int> heartbeats_from_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST(DdsCommander, WaitsForTheServerToHearEveryAgentNotOnlyItself) {
  DdsConfig cfg;
  cfg.domain_id = random_test_domain();
  FakeSwarm swarm(cfg);
  swarm.server_hears(5);  // drone 0 matched the ground station, not yet the server
  DdsCommander gs(GroundStationConfig{}, cfg);

  const double until = wall_seconds() + 10;
  while (gs.status().drones_online < 6 && wall_seconds() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_EQ(gs.status().drones_online, 6) << "the ground station never heard the six heartbeats";
  EXPECT_FALSE(gs.wait_for_swarm(6, 1.0));
  // `wait-agents` too: a take-off sent now would reach drone 0 ticks after
  // the others, and a lockstep run with the same seed would fly differently.
  EXPECT_FALSE(gs.wait_for_online(6, 1.0));
  const auto st = gs.status();
  EXPECT_EQ(st.drones_online, 6);
  EXPECT_EQ(st.drones_server_hears, 5);

  swarm.server_hears(6);
  EXPECT_TRUE(gs.wait_for_online(6, 10.0));
  EXPECT_TRUE(gs.wait_for_swarm(6, 10.0));
}

// `ddswarm-gs status` is a new participant: it meets the agents one by one,
// and on a loaded machine a second after the server's status it had heard
// only drones 3-5, so a mixed swarm's status named one law. It waits for every
// agent the server hears live, and not for one the server does not.
TEST(DdsCommander, StatusWaitsForEveryLiveAgentsHeartbeat) {
  DdsConfig cfg;
  cfg.domain_id = random_test_domain();
  {
    FakeSwarm swarm(cfg);
    swarm.server_hears(6);
    swarm.heartbeats_from(3);  // drones 0-2 not yet met
    DdsCommander gs(GroundStationConfig{}, cfg);
    ASSERT_TRUE(gs.wait_for_status(10.0));
    EXPECT_FALSE(gs.wait_agent_statuses(0.5));
    std::thread meet([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(1500));
      swarm.heartbeats_from(0);
    });
    const double t0 = wall_seconds();
    EXPECT_TRUE(gs.wait_agent_statuses(10.0));
    meet.join();
    EXPECT_EQ(gs.status().laws, "3 reynolds, 3 thesis");
    EXPECT_GE(wall_seconds() - t0, 1.0);
  }
  // Drone 0's agent is dead: the server does not list it, and the wait does
  // not sit out its timeout for it.
  FakeSwarm swarm(cfg);
  swarm.server_hears(5);
  swarm.heartbeats_from(1);
  DdsCommander gs(GroundStationConfig{}, cfg);
  ASSERT_TRUE(gs.wait_for_status(10.0));
  const double t1 = wall_seconds();
  EXPECT_TRUE(gs.wait_agent_statuses(10.0));
  EXPECT_LT(wall_seconds() - t1, 5.0);
  EXPECT_EQ(gs.status().laws, "3 reynolds, 2 thesis");
}

// A take-off ends for an agent once either word has it past the climb. A
// heartbeat the agent sent mid-climb, then the server's newer word that it
// holds: over, with no wait for the agent's next heartbeat (a quarter second
// in half of Table 1's runs when the heartbeat outweighed the server).
TEST(ClimbOver, EitherWordPastTheClimbEndsIt) {
  EXPECT_TRUE(climb_over({Phase::kTakeoff, Phase::kHold}));
  EXPECT_TRUE(climb_over({Phase::kHold, Phase::kTakeoff}));
  EXPECT_TRUE(climb_over({Phase::kHold, std::nullopt}));
  EXPECT_TRUE(climb_over({std::nullopt, Phase::kHold}));
  EXPECT_FALSE(climb_over({Phase::kTakeoff, Phase::kTakeoff}));
  EXPECT_FALSE(climb_over({Phase::kTakeoff, std::nullopt}));
  EXPECT_FALSE(climb_over({std::nullopt, Phase::kIdle}));  // accepted, not yet climbing
  EXPECT_FALSE(climb_over({std::nullopt, std::nullopt}));  // no word since the command
}

// An experiment's run whose server died at start-up: the wait ends at once,
// not after its timeout (which would cost a minute per run).
// "No server" only when none was discovered: a server whose participant is
// known but not yet heard (a secure handshake, endpoints still matching) is
// coming up, and a ground station waits on for it (join_swarm).
TEST(ServerSearch, TellsNothingThereFromStillComingUp) {
  using State = ServerSearch::State;
  auto none = server_search({}, false, false);
  EXPECT_EQ(none.state, State::kNothing);
  EXPECT_EQ(none.found, "no server's participant discovered");
  auto handshaking = server_search({{12.4, -1}}, true, false);
  EXPECT_EQ(handshaking.state, State::kComingUp);
  EXPECT_EQ(handshaking.found,
            "a server's participant discovered 12 s ago, its DDS Security handshake not passed");
  // The newest of two (a restarted server): oldest first, as peers_named gives them.
  auto matching = server_search({{30, 0.5}, {3, 0.2}}, true, false);
  EXPECT_EQ(matching.state, State::kComingUp);
  EXPECT_EQ(matching.found,
            "a server's participant discovered 3 s ago, none of its status heard yet");
  // Without DDS Security nothing is under way: a secure swarm's server, or
  // one this process cannot reach. Waiting would not mend it.
  auto unheard = server_search({{3, -1}}, false, false);
  EXPECT_EQ(unheard.state, State::kUnheard);
  EXPECT_EQ(unheard.found,
            "a server's participant discovered 3 s ago, none of its status heard (a secure swarm "
            "needs --secure)");
  EXPECT_EQ(server_search({{3, -1}}, true, true).state, State::kHeard);
}

// On an empty domain the search finds nothing; a server's participant that
// publishes no status is found, and said so.
TEST(DdsCommander, TellsAnEmptyDomainFromAnUnheardServer) {
  DdsConfig cfg;
  cfg.domain_id = random_test_domain();
  DdsCommander gs(GroundStationConfig{}, cfg);
  EXPECT_FALSE(gs.wait_for_server(0.5));
  EXPECT_EQ(gs.server_search().state, ServerSearch::State::kNothing);
  Participant server(cfg, kServerParticipantName);  // no status writer yet
  const double until = wall_seconds() + 10;
  while (gs.server_search().state == ServerSearch::State::kNothing && wall_seconds() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(gs.server_search().state, ServerSearch::State::kUnheard);
  EXPECT_FALSE(gs.wait_for_server(0.3));
}

TEST(DdsCommander, StopsWaitingForTheSwarmWhenToldToGiveUp) {
  DdsConfig cfg;
  cfg.domain_id = random_test_domain();
  DdsCommander gs(GroundStationConfig{}, cfg);  // no swarm at all
  std::atomic<int> asked{0};
  const double t0 = wall_seconds();
  EXPECT_FALSE(gs.wait_for_swarm(6, 30.0, [&] { return ++asked >= 3; }));
  EXPECT_LT(wall_seconds() - t0, 2.0);
  EXPECT_GE(asked.load(), 3);
  EXPECT_FALSE(gs.wait_for_swarm(6, 0.3, [] { return false; }));  // a plain timeout still is one
}

// A run whose swarm never came up (e.g. the server hears none of six
// agents the ground station hears) is a start-up failure: the experiment
// starts it again, up to kRunStarts times; any other failure is its result.
TEST(Experiment, ARunWhoseSwarmNeverCameUpStartsAgain) {
  DdsConfig cfg;
  cfg.domain_id = random_test_domain();
  DdsCommander gs(GroundStationConfig{}, cfg);  // no swarm at all
  const TaskOutcome o = fly_task(
      gs, 6, TaskConfig{}, nullptr, [] { return false; }, 0.3);
  EXPECT_FALSE(o.ok);
  EXPECT_TRUE(o.never_up);
  EXPECT_EQ(o.reason, "only 0/6 agents online (0 heard by the server) after 0.3 s");
  EXPECT_TRUE(start_run_again(o, false, 1));
  EXPECT_TRUE(start_run_again(o, false, kRunStarts - 1));
  EXPECT_FALSE(start_run_again(o, false, kRunStarts));
  EXPECT_FALSE(start_run_again(o, true, 1));  // a process died: that is the run's result
  const TaskOutcome died = fly_task(
      gs, 6, TaskConfig{}, nullptr, [] { return true; }, 0.3);
  EXPECT_FALSE(died.never_up);
  EXPECT_FALSE(start_run_again(died, false, 1));
  // The experiment runner, which has already waited, asks for the same outcome.
  const TaskOutcome waited = swarm_not_up(gs, 6, 30.0);
  EXPECT_TRUE(waited.never_up);
  EXPECT_EQ(waited.reason, "only 0/6 agents online (0 heard by the server) after 30 s");
  TaskOutcome refused;
  refused.reason = "task: refused";
  EXPECT_FALSE(start_run_again(refused, false, 1));
}

// The result line: the texts scripts grep stay as they were, the swarm
// metrics follow them, and what was not measured reads n/a.
TEST(TaskOutcome, ResultLineKeepsItsTextsAndAddsTheSwarmMetrics) {
  TaskOutcome o;
  o.ok = true;
  o.task_time_s = 81.06;
  o.wall_time_s = 2.9;
  o.drones = 6;
  o.speed_mps = 0.8;
  o.min_inter_drone_m = 1.9;
  o.min_clearance_m = 0.85;
  o.metrics.order_mean = 0.934;
  o.metrics.order_min = -0.12;
  o.metrics.speed_mean_mps = 0.781;
  o.metrics.near_misses = 2;
  o.metrics.components_max = 1;
  o.metrics.lambda2_min = 1.234;
  EXPECT_EQ(o.line(),
            "task complete: 81.06 s sim time (wall 2.9 s), 6 drones at 0.80 m/s, collisions: "
            "obstacle 0, drone 0, ground 0; min inter-drone distance 1.90 m, min obstacle "
            "clearance 0.85 m; order 0.93 (min -0.12), mean speed 0.78 m/s, near misses 2, "
            "components max 1, lambda2 min 1.23");
  o.metrics.lambda2_min = std::nan("");  // above sim.metrics_lambda2_max_drones
  o.lost_drones = {3};
  EXPECT_NE(o.line().find("lambda2 min n/a; lost drones (agent lost, failsafe): 3"),
            std::string::npos)
      << o.line();
}

}  // namespace
}  // namespace ddswarm::gs
