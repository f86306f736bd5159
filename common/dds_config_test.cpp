#include "common/dds_config.hpp"
#include "common/config_reference.hpp"
#include "common/yaml_section.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/config_error.hpp"

namespace ddswarm {
namespace {

namespace fs = std::filesystem;

/// A directory holding what scripts/make-certs writes for one role (empty files).
class SecureDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::temp_directory_path() / ("ddswarm-dds-config-test-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    for (const char* f : {"identity_ca.cert.pem", "permissions_ca.cert.pem", "governance.p7s",
                          "agent-2.permissions.p7s", "agent-2.cert.pem", "agent-2.key.pem"})
      std::ofstream(dir / f) << "x";
  }
  void TearDown() override { fs::remove_all(dir); }
  DdsConfig secure(const std::string& role) {
    DdsConfig c;
    c.security_dir = dir.string();
    c.security_role = role;
    return c;
  }
  fs::path dir;
};

TEST_F(SecureDir, OffByDefault) {
  DdsConfig c;
  EXPECT_FALSE(c.secure());
  EXPECT_NO_THROW(c.validate());
}

TEST_F(SecureDir, CompleteRoleValidates) {
  auto c = secure("agent-2");
  EXPECT_TRUE(c.secure());
  EXPECT_NO_THROW(c.validate());
  auto files = c.security_files();
  ASSERT_EQ(files.size(), 6u);
  EXPECT_EQ(fs::path(files[3]).filename(), "agent-2.permissions.p7s");
  EXPECT_EQ(fs::path(files[5]).filename(), "agent-2.key.pem");
}

TEST_F(SecureDir, MissingFilesAreNamedInOneLine) {
  auto c = secure("agent-3");
  try {
    c.validate();
    FAIL() << "missing credentials accepted";
  } catch (const FieldError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.field(), "dds.secure");
    EXPECT_NE(what.find("agent-3.permissions.p7s, agent-3.cert.pem, agent-3.key.pem"),
              std::string::npos)
        << what;
    EXPECT_EQ(what.find("identity_ca"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// Fast DDS 2.9's discovery server has no DDS Security: a secure client of
// one aborts on an assertion (SecurityManager.cpp:2272) instead of joining.
TEST_F(SecureDir, ADiscoveryServerIsRefusedUnderSecurity) {
  auto c = secure("agent-2");
  c.discovery = Discovery::kDiscoveryServer;
  c.discovery_server = "127.0.0.1:11811";
  try {
    c.validate();
    FAIL() << "a secure discovery-server client accepted";
  } catch (const FieldError& e) {
    EXPECT_EQ(e.field(), "dds.discovery_server");
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:11811"), std::string::npos) << e.what();
  }
  c.security_dir.clear();
  EXPECT_NO_THROW(c.validate());
}

TEST_F(SecureDir, BadOrMissingRoleRejected) {
  EXPECT_THROW(secure("").validate(), FieldError);
  EXPECT_THROW(secure("../agent-2").validate(), FieldError);
}

TEST(OneShotLease, ACommandThatComesAndGoesOutlivesNoPeersLeaseTimer) {
  // At the default 3 s lease a `status` of about 3 s can leave as its peers'
  // timers fire. It announces itself as often as at that lease, every second.
  const DdsConfig c = one_shot(DdsConfig{});
  EXPECT_EQ(c.lease_duration_s, kOneShotLeaseS);
  EXPECT_DOUBLE_EQ(c.announcement_period_s, 1.0);
  EXPECT_NO_THROW(c.validate());
  DdsConfig longer;
  longer.lease_duration_s = 60.0;  // a longer configured lease is kept
  EXPECT_EQ(one_shot(longer).lease_duration_s, 60.0);
  EXPECT_DOUBLE_EQ(one_shot(longer).announcement_period_s, 20.0);
}

TEST(OneShotLease, AnAnnouncementPeriodNotShorterThanTheLeaseIsNamed) {
  DdsConfig c;
  c.announcement_period_s = 3.0;
  try {
    c.validate();
    FAIL() << "accepted";
  } catch (const FieldError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("dds.announcement_period_s"), std::string::npos) << what;
  }
}

TEST(DdsConfigSecurity, DefaultRoleKeepsTheUsersChoice) {
  DdsConfig c;
  default_security_role(c, "server");
  EXPECT_EQ(c.security_role, "server");
  default_security_role(c, "gs");
  EXPECT_EQ(c.security_role, "server");
  EXPECT_EQ(drone_partition(7), "drone/7");
}

TEST(DdsConfig, ShmHealthCheckOutOfRangeIsNamed) {
  DdsConfig c;
  EXPECT_EQ(c.shm_health_check_s, kShmHealthCheckS);
  for (double bad : {0.0, 0.05, 61.0, std::nan("")}) {
    c.shm_health_check_s = bad;
    try {
      c.validate();
      FAIL() << "dds.shm_health_check_s = " << bad << " accepted";
    } catch (const FieldError& e) {
      EXPECT_EQ(e.field(), "dds.shm_health_check_s");
    }
  }
  c.shm_health_check_s = 0.1;
  EXPECT_NO_THROW(c.validate());
}

TEST(DdsConfig, TheReferenceDescribesEveryFieldAsTheCodeDeclaresIt) {
  EXPECT_EQ(reference_mismatches(configuration_reference(), "### `dds:`", field_rows<DdsConfig>()),
            std::vector<std::string>{});
}

TEST(IdsAboveAgents, NoAgentTakesOrAnnouncesToThemAndTheirPortsAreValid) {
  for (const int domain : {0, 30, 89, 200}) {
    const auto ids = participant_ids_above_agents(domain);
    ASSERT_EQ(ids.size(), static_cast<std::size_t>(kAboveAgentsIds)) << "domain " << domain;
    EXPECT_EQ(ids.front(), max_participant_id(domain));  // the top one first
    for (const int id : ids) {
      EXPECT_GE(id, kAgentParticipantIdBase + 1024);  // above drone 1023's agent
      EXPECT_LE(rtps_unicast_port(domain, id) + 1, 65535);
    }
  }
  // Domain 0's lie above Linux's default ephemeral range (32768-60999).
  EXPECT_GT(rtps_unicast_port(0, participant_ids_above_agents(0).back()), 60999);
  // The last domain has no room above 1024 agents: such a participant meets them.
  EXPECT_TRUE(participant_ids_above_agents(232).empty());
}

TEST(SecureLease, ASecureSwarmOnOneHostTakesTheLongLeaseUnlessTheScenarioNamesOne) {
  DdsConfig plain;
  load(YamlSection(YAML::Load("domain_id: 3"), "s.yaml", "dds"), plain);
  DdsConfig secure = plain;
  secure.security_dir = "certs";
  secure_lease(secure);
  EXPECT_EQ(secure.lease_duration_s, kSecureLeaseS);
  secure_lease(plain);  // without Security nothing changes
  EXPECT_EQ(plain.lease_duration_s, 3.0);
  DdsConfig named;
  load(YamlSection(YAML::Load("lease_duration_s: 5"), "s.yaml", "dds"), named);
  named.security_dir = "certs";
  secure_lease(named);
  EXPECT_EQ(named.lease_duration_s, 5.0);  // the user's word stands
  DdsConfig peers = secure;
  peers.lease_duration_s = 3.0;
  peers.discovery = Discovery::kPeers;  // an opted-in network: not one host
  secure_lease(peers);
  EXPECT_EQ(peers.lease_duration_s, 3.0);
}

}  // namespace
}  // namespace ddswarm
