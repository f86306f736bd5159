#include "launcher/launcher.hpp"

#include "common/config_error.hpp"
#include "common/dds_config.hpp"

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <map>
#include <thread>

using namespace ddswarm::gs;

TEST(Launcher, ReportsWhichChildDiedAndWhy) {
  Launcher l(::testing::TempDir() + "/launcher_logs");
  l.start({"quitter", {"/bin/sh", "-c", "echo bye; exit 3"}});
  pid_t sleeper = l.start({"sleeper", {"/bin/sleep", "30"}});
  std::vector<ChildExit> exits;
  for (int i = 0; i < 100 && exits.empty(); ++i) {
    exits = l.reap();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(exits.size(), 1u);
  EXPECT_EQ(exits[0].describe().substr(0, 8), "quitter ");
  EXPECT_EQ(exits[0].exit_code, 3);
  ASSERT_TRUE(l.signal("sleeper", SIGKILL));
  exits.clear();
  for (int i = 0; i < 100 && exits.empty(); ++i) {
    exits = l.reap();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_EQ(exits.size(), 1u);
  EXPECT_EQ(exits[0].pid, sleeper);
  EXPECT_NE(exits[0].describe().find("killed by SIGKILL"), std::string::npos);
}

// The experiment's set check: a program's whole output and its exit code.
TEST(Launcher, RunToEndCollectsOutputAndExitCode) {
  std::string out;
  const ChildExit e =
      run_to_end({"sh", {"/bin/sh", "-c", "echo said; echo 'error: bad' >&2; exit 3"}}, out);
  EXPECT_EQ(e.exit_code, 3);
  EXPECT_EQ(e.signal, 0);
  EXPECT_EQ(out, "said\nerror: bad\n");
  EXPECT_EQ(run_to_end({"true", {"/bin/true"}}, out).exit_code, 0);
  EXPECT_EQ(out, "");
  EXPECT_THROW(run_to_end({"none", {"/no/such/program"}}, out), std::runtime_error);
}

TEST(Launcher, ReadsTheDiscoveryServersDroppedParticipants) {
  // As fast-discovery-server 2.9 prints its errors, colours and all.
  auto logged = [](const std::string& message, const std::string& function) {
    return "\x1b[37;1m2026-11-21 21:17:38.547 \x1b[31;1m[\x1b[37;1mDISCOVERY_DATABASE\x1b[31;1m "
           "Error] \x1b[37m" +
           message + "\x1b[34;1m -> Function \x1b[36m" + function + "\x1b[m";
  };
  const std::string line = logged(
      "Writer 01.0f.78.fd.33.40.d6.23.25.00.00.00|0.0.1.2 has no associated participant. Skipping",
      "create_writers_from_change_");
  auto p = dropped_participant_prefix(line);
  ASSERT_TRUE(p);
  const std::array<std::uint8_t, 12> want = {0x01, 0x0f, 0x78, 0xfd, 0x33, 0x40,
                                             0xd6, 0x23, 0x25, 0,    0,    0};
  EXPECT_EQ(*p, want);
  EXPECT_EQ(prefix_pid16(*p), 16435);  // the agent's pid in that run, 0x4033
  EXPECT_FALSE(dropped_participant_prefix(
      "Attempting to delete and orphan reader -> Function delete_reader_entity_"));
  EXPECT_FALSE(dropped_participant_prefix("### Server is running ###"));
  EXPECT_FALSE(dropped_participant_prefix(
      "Writer 01.0f.zz|0.0.1.2 has no associated participant. Skipping"));
  const std::string unmatched = logged(
      "Matching unexisting participant from writer 01.0f.78.fd.b5.74.d4.24.00.00.00.00|0.0.1.3",
      "match_writer_reader_");
  auto u = unmatched_participant_prefix(unmatched);
  ASSERT_TRUE(u);
  EXPECT_EQ(prefix_pid16(*u), 0x74b5);
  EXPECT_FALSE(dropped_participant_prefix(unmatched));
  EXPECT_FALSE(unmatched_participant_prefix(line));
}

TEST(Launcher, AsksAnAgentWhoseEndpointsTheDiscoveryServerDroppedToJoinAgain) {
  Launcher l(::testing::TempDir() + "/launcher_drop_logs");
  l.rejoin_dropped_participants("discovery-server");
  // Children that exit with a code of their own on SIGUSR1.
  auto on_usr1 = [](int code) {
    return std::vector<std::string>{
        "/bin/sh", "-c",
        "trap 'exit " + std::to_string(code) + "' USR1; while :; do sleep 0.05; done"};
  };
  const pid_t agent5 = l.start({"agent 5", on_usr1(42)});
  const pid_t agent6 = l.start({"agent 6", on_usr1(43)});
  const pid_t sim = l.start({"sim", on_usr1(44)});
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // all have their traps
  auto guid = [](pid_t pid) {
    char g[64];
    std::snprintf(g, sizeof g, "01.0f.78.fd.%02x.%02x.d6.23.25.00.00.00", pid & 0xff,
                  (pid >> 8) & 0xff);
    return std::string(g);
  };
  // Agent 5's endpoints dropped (twice: one signal); "Matching unexisting
  // participant" for agent 6, which may just have left: no signal; for the
  // server, which never leaves by itself: a signal.
  const std::string dropped =
      "Writer " + guid(agent5) + "|0.0.1.2 has no associated participant. Skipping";
  const std::string unmatched6 =
      "Matching unexisting participant from writer " + guid(agent6) + "|0.0.1.3";
  const std::string unmatched_sim =
      "Matching unexisting participant from reader " + guid(sim) + "|0.0.4.7";
  l.start({"discovery-server",
           {"/bin/sh", "-c",
            "echo '" + dropped + "'; echo '" + dropped + "'; echo '" + unmatched6 + "'; echo '" +
                unmatched_sim + "'; sleep 30"}});
  std::map<pid_t, int> codes;
  for (int i = 0; i < 150 && codes.size() < 2; ++i) {
    for (const auto& e : l.reap()) codes[e.pid] = e.exit_code;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  for (const auto& e : l.reap()) codes[e.pid] = e.exit_code;
  EXPECT_EQ(codes.size(), 2u);
  EXPECT_EQ(codes[agent5], 42);
  EXPECT_EQ(codes[sim], 44);
  EXPECT_EQ(codes.count(agent6), 0u) << "agent 6 was asked to join again";
  l.stop_all(0.5);
}

// ddswarm-launch and the experiment runner start the agents once their
// recorder says it hears the server (kRecorderMatchedServer).
TEST(Launcher, WaitsUntilAChildSaysItIsReadyOrEnds) {
  Launcher l(::testing::TempDir() + "/launcher_ready_logs");
  l.start({"late",
           {"/bin/sh", "-c", "echo starting; sleep 0.3; echo now ready here; sleep 30"},
           "ready here"});
  l.start({"mute", {"/bin/sleep", "30"}, "ready here"});
  l.start({"quits", {"/bin/sh", "-c", "echo error: no disk; exit 1"}, "ready here"});
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_TRUE(l.wait_ready("late", 10));
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(250));
  EXPECT_FALSE(l.wait_ready("mute", 0.3));  // never says it: the timeout ends the wait
  const auto t1 = std::chrono::steady_clock::now();
  EXPECT_FALSE(l.wait_ready("quits", 10));  // ended without saying it: no need to wait on
  EXPECT_LT(std::chrono::steady_clock::now() - t1, std::chrono::seconds(5));
  EXPECT_FALSE(l.wait_ready("nobody", 10));
  l.stop_all(1.0);
}

TEST(Launcher, StopAllLeavesNoChildBehind) {
  std::vector<pid_t> pids;
  {
    Launcher l;
    for (int i = 0; i < 4; ++i)
      pids.push_back(l.start({"s" + std::to_string(i), {"/bin/sleep", "30"}}));
    // One child ignores SIGTERM: stop_all must still end it.
    pids.push_back(l.start({"stubborn", {"/bin/sh", "-c", "trap '' TERM; sleep 30"}}));
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    auto exits = l.stop_all(0.5);
    EXPECT_EQ(exits.size(), 5u);
    EXPECT_EQ(l.running(), 0);
  }
  for (pid_t p : pids) EXPECT_NE(kill(p, 0), 0) << "pid " << p << " survived";
}

TEST(Launcher, IdRanges) {
  EXPECT_EQ(parse_id_ranges("3-5,7", 10), (std::vector<int>{3, 4, 5, 7}));
  EXPECT_THROW(parse_id_ranges("5-3", 10), std::invalid_argument);
  EXPECT_THROW(parse_id_ranges("1-12", 10), std::invalid_argument);
  EXPECT_THROW(parse_id_ranges("x", 10), std::invalid_argument);
}

TEST(Launcher, AgentHostSharesSplitTheIdsContiguously) {
  using V = std::vector<std::string>;
  EXPECT_EQ(agent_host_shares({0, 1, 2, 3, 4, 5}, 2), (V{"0,1,2", "3,4,5"}));
  EXPECT_EQ(agent_host_shares({0, 1, 2, 3, 4}, 2), (V{"0,1,2", "3,4"}));
  EXPECT_EQ(agent_host_shares({3, 4, 5, 7}, 3),
            (V{"3,4", "5,7"}));                            // ceil(4/3) = 2 per host: two hosts
  EXPECT_EQ(agent_host_shares({0, 1}, 5), (V{"0", "1"}));  // never an empty host
  EXPECT_EQ(agent_host_shares({0, 1, 2}, 1), (V{"0,1,2"}));
  EXPECT_TRUE(agent_host_shares({0, 1, 2}, 0).empty());  // 0: one process per drone
  EXPECT_TRUE(agent_host_shares({}, 2).empty());
}

TEST(Launcher, AgentsStartedWithTheirServerSkipTheDuplicateProbe) {
  using V = std::vector<std::string>;
  EXPECT_EQ(agent_command("b", "3", false, "s.yaml", true),
            (V{"b/ddswarm-agent", "--id", "3", "--config", "s.yaml", "--duplicate-probe", "0"}));
  EXPECT_EQ(agent_command("b", "0,1,2", true, "s.yaml", false),
            (V{"b/ddswarm-agent", "--ids", "0,1,2", "--config", "s.yaml"}));
}

TEST(Launcher, RestartsOnlyWhatStartingAgainCanMend) {
  const auto exit_with = [](int code) { return ChildExit{"agent 2", 42, code, 0}; };
  EXPECT_TRUE(worth_restarting(ChildExit{"agent 2", 42, -1, SIGABRT}));  // a crash
  EXPECT_TRUE(worth_restarting(ChildExit{"agent 2", 42, -1, SIGKILL}));  // an OOM kill, a user
  EXPECT_TRUE(worth_restarting(exit_with(1)));                           // an error at run time
  EXPECT_FALSE(worth_restarting(exit_with(0)));                          // its --duration ended
  EXPECT_FALSE(worth_restarting(exit_with(2)));  // its configuration: it would fail again
  EXPECT_FALSE(worth_restarting(exit_with(3)));  // another agent flies its drone
}

// --on-death restart: a crashed agent flies again up to kMaxRestarts times;
// its next crash, or any end of a process that is no agent, stops everything.
TEST(DeathPolicy, RestartsACrashedAgentThreeTimesThenStops) {
  DeathPolicy p(OnDeath::kRestart);
  const ChildSpec agent{"agent 2", {"b/ddswarm-agent", "--id", "2"}};
  p.restartable(agent);
  const ChildExit crash{"agent 2", 42, -1, SIGABRT};
  for (int k = 1; k <= kMaxRestarts; ++k) {
    const auto again = p.ended(crash);
    ASSERT_TRUE(again.has_value()) << "restart " << k;
    EXPECT_EQ(again->argv, agent.argv);
    EXPECT_EQ(p.restarts("agent 2"), k);
    EXPECT_FALSE(p.stop());
  }
  EXPECT_FALSE(p.ended(crash).has_value());
  EXPECT_TRUE(p.died());
  EXPECT_TRUE(p.stop());
}

TEST(DeathPolicy, RestartsNeitherTheServerNorAnAgentThatWouldFailAgain) {
  DeathPolicy server_died(OnDeath::kRestart);
  server_died.restartable({"agent 0", {"b/ddswarm-agent"}});
  EXPECT_FALSE(server_died.ended({"sim", 7, -1, SIGSEGV}).has_value());
  EXPECT_TRUE(server_died.stop());

  DeathPolicy bad_config(OnDeath::kRestart);
  bad_config.restartable({"agent 0", {"b/ddswarm-agent"}});
  EXPECT_FALSE(bad_config.ended({"agent 0", 8, 2, 0}).has_value());  // exit 2: its configuration
  EXPECT_TRUE(bad_config.stop());
  EXPECT_EQ(bad_config.restarts("agent 0"), 0);
}

TEST(DeathPolicy, StopStopsAtTheFirstDeathAndKeepNever) {
  DeathPolicy stop(OnDeath::kStop);
  stop.restartable({"agent 0", {"b/ddswarm-agent"}});
  EXPECT_FALSE(stop.stop());
  EXPECT_FALSE(stop.ended({"agent 0", 9, -1, SIGKILL}).has_value());
  EXPECT_TRUE(stop.stop());

  DeathPolicy keep(OnDeath::kKeep);
  keep.restartable({"agent 0", {"b/ddswarm-agent"}});
  EXPECT_FALSE(keep.ended({"agent 0", 9, -1, SIGKILL}).has_value());
  EXPECT_FALSE(keep.ended({"sim", 10, 1, 0}).has_value());
  EXPECT_TRUE(keep.died());
  EXPECT_FALSE(keep.stop());
}

TEST(DeathPolicy, RestartsACrashedDiscoveryServerWhateverThePolicy) {
  const ChildSpec ds{"discovery-server", {"/usr/bin/fast-discovery-server", "-p", "4242"}};
  for (OnDeath policy : {OnDeath::kStop, OnDeath::kKeep, OnDeath::kRestart}) {
    DeathPolicy p(policy);
    p.always_restart(ds);
    const ChildExit abort{"discovery-server", 11, -1, SIGABRT};  // Fast DDS 2.9.1's assertion
    for (int k = 1; k <= kMaxRestarts; ++k) {
      const auto again = p.ended(abort);
      ASSERT_TRUE(again.has_value()) << "restart " << k;
      EXPECT_EQ(again->argv, ds.argv) << "the same port, so every client finds it again";
      EXPECT_FALSE(p.stop());
    }
    EXPECT_FALSE(p.ended(abort).has_value()) << "a server that keeps dying is a death";
    EXPECT_EQ(p.stop(), policy != OnDeath::kKeep);
  }
  DeathPolicy clean_exit(OnDeath::kStop);
  clean_exit.always_restart(ds);
  EXPECT_FALSE(clean_exit.ended({"discovery-server", 12, 0, 0}).has_value());
  EXPECT_TRUE(clean_exit.stop());
}

TEST(DeathPolicy, ParsesTheOptionAndNamesABadValue) {
  EXPECT_EQ(parse_on_death("stop"), OnDeath::kStop);
  EXPECT_EQ(parse_on_death("keep"), OnDeath::kKeep);
  EXPECT_EQ(parse_on_death("restart"), OnDeath::kRestart);
  try {
    parse_on_death("resurrect");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--on-death = resurrect"), std::string::npos) << e.what();
  }
}

TEST(Launcher, MissingProgramIsAClearError) {
  Launcher l;
  try {
    l.start({"ghost", {"/no/such/program"}});
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/program"), std::string::npos);
  }
}

TEST(Launcher, DiscoveryServerChoice) {
  using K = DiscoveryServerChoice::Kind;
  EXPECT_EQ(parse_discovery_server("auto").kind, K::kAuto);
  EXPECT_EQ(parse_discovery_server("on").kind, K::kOn);
  EXPECT_EQ(parse_discovery_server("off").kind, K::kOff);
  auto ext = parse_discovery_server("10.0.0.2:11811");
  EXPECT_EQ(ext.kind, K::kExternal);
  EXPECT_EQ(ext.address, "10.0.0.2:11811");
  for (const char* bad :
       {"", "yes", "10.0.0.2", "10.0.0.2:", "10.0.0.2:x", "10.0.0.2:70000", "host:11811"})
    EXPECT_THROW(parse_discovery_server(bad), std::invalid_argument) << bad;
  // auto: only a large swarm whose every process this launcher starts on this machine.
  const auto a = parse_discovery_server("auto");
  EXPECT_FALSE(wants_local_discovery_server(a, kAutoDiscoveryServerAbove, true, true));
  EXPECT_TRUE(wants_local_discovery_server(a, kAutoDiscoveryServerAbove + 1, true, true));
  EXPECT_FALSE(wants_local_discovery_server(a, 128, false, true));
  EXPECT_FALSE(wants_local_discovery_server(a, 128, true, false));
  EXPECT_TRUE(wants_local_discovery_server(parse_discovery_server("on"), 1, true, true));
  EXPECT_FALSE(wants_local_discovery_server(parse_discovery_server("off"), 128, true, true));
  EXPECT_FALSE(wants_local_discovery_server(ext, 128, true, true));
}

TEST(Launcher, LargeSwarmsAgentsGetExplicitParticipantIds) {
  EXPECT_EQ(agent_participant_id(kExplicitParticipantIdsAbove, 0), -1);  // automatic ids suffice
  EXPECT_EQ(agent_participant_id(110, 0), kFirstAgentParticipantId);
  EXPECT_EQ(agent_participant_id(110, 109), kFirstAgentParticipantId + 109);
  EXPECT_EQ(agent_participant_id(128, 127), kFirstAgentParticipantId + 127);
  EXPECT_EQ(agent_participant_id(1024, 1023), kFirstAgentParticipantId + 1023);
  EXPECT_LE(agent_participant_id(1024, 1023), kMaxParticipantId);
}

TEST(Launcher, WarnsWhenExplicitIdsUseEphemeralPorts) {
  // 128 agents (ids 32-159) in domain 150: ports 44974-45229, inside Linux's 32768-60999.
  const std::string w = ephemeral_port_warning(150, 32, 159, {32768, 60999});
  EXPECT_NE(w.find("ports 44974-45229"), std::string::npos) << w;
  EXPECT_NE(w.find("use --domain 100 or lower"), std::string::npos) << w;
  // The advice holds: domain 100 keeps every port below the range; 101 does not.
  EXPECT_EQ(ephemeral_port_warning(100, 32, 159, {32768, 60999}), "");
  EXPECT_NE(ephemeral_port_warning(101, 32, 159, {32768, 60999}), "");
  EXPECT_EQ(ephemeral_port_warning(0, 4, 1027, {32768, 60999}), "");
}

TEST(Launcher, ParticipantIdsFitTheRtpsPortsOfTheirDomain) {
  using namespace ddswarm;
  EXPECT_EQ(max_participant_id(0), 29062);
  EXPECT_EQ(max_participant_id(232), 62);
  DdsConfig c;
  c.profiles_file = DDSWARM_CONFIG_DIR "/dds_profiles.xml";
  c.participant_id = 1027;  // the launcher's id for drone 1023
  c.domain_id = 100;
  EXPECT_NO_THROW(c.validate());
  c.domain_id = 232;
  EXPECT_THROW(c.validate(), FieldError);
}
