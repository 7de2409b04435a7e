// Who may open a WebSocket on the bridge: its own page and programs, pages the launch file
// lists; never another page in a browser here, nor one whose name was made to point here.
#include <gtest/gtest.h>

#include <algorithm>

#include "viewer/foxglove_bridge/origin_policy.hpp"

namespace mocap::foxglove {
namespace {

OriginPolicy policy(std::vector<std::string> allowed_origins = {}) {
  return OriginPolicy({.port = 8765,
                       .tls = false,
                       .hosts = {"localhost", "127.0.0.1", "::1", "mocap-pc", "Lab-Proxy:443"},
                       .allowed_origins = std::move(allowed_origins)});
}

TEST(OriginPolicy, TakesProgramsAndTheBridgesOwnPage) {
  const OriginPolicy bridge = policy();
  EXPECT_EQ(bridge.refuse("127.0.0.1:8765", ""), std::nullopt);  // no Origin: not a browser
  EXPECT_EQ(bridge.refuse("localhost:8765", "http://localhost:8765"), std::nullopt);
  EXPECT_EQ(bridge.refuse("127.0.0.1:8765", "http://localhost:8765"), std::nullopt);
  EXPECT_EQ(bridge.refuse("[::1]:8765", "http://[::1]:8765"), std::nullopt);
  EXPECT_EQ(bridge.refuse("MOCAP-PC:8765", "https://Mocap-PC:8765"), std::nullopt);
  EXPECT_EQ(bridge.refuse("lab-proxy", ""), std::nullopt);  // a listed host, any port
}

TEST(OriginPolicy, RefusesOtherPagesUnlessListed) {
  const OriginPolicy bridge = policy();
  for (const char* origin : {"https://app.foxglove.dev", "http://attacker.example",
                             "http://localhost:8080",  // this machine, another server
                             "http://localhost", "null", "file://", "http://127.0.0.1:8765.x"}) {
    const std::optional<std::string> why = bridge.refuse("127.0.0.1:8765", origin);
    ASSERT_TRUE(why) << origin;
    EXPECT_NE(why->find("list it in allowed_origins"), std::string::npos) << *why;
  }
  const OriginPolicy listed = policy({"https://app.foxglove.dev", "file://", "null"});
  EXPECT_EQ(listed.refuse("127.0.0.1:8765", "https://app.foxglove.dev"), std::nullopt);
  EXPECT_EQ(listed.refuse("127.0.0.1:8765", "file://"), std::nullopt);
  EXPECT_EQ(listed.refuse("127.0.0.1:8765", "null"), std::nullopt);
  EXPECT_TRUE(listed.refuse("127.0.0.1:8765", "https://app.foxglove.dev.attacker.example"));
}

// DNS rebinding: the attacker's page, loaded from its own name, is answered by this machine. Its
// Origin is its own name with the bridge's port: only the Host header gives it away.
TEST(OriginPolicy, RefusesAHostThatIsNotThisServers) {
  const OriginPolicy bridge = policy();
  const std::optional<std::string> why =
      bridge.refuse("attacker.example:8765", "http://attacker.example:8765");
  ASSERT_TRUE(why);
  EXPECT_EQ(*why,
            "Host 'attacker.example:8765' is not a name of this server (a page whose name was made "
            "to point here?); if it is yours, list 'attacker.example' in allowed_hosts");
  EXPECT_TRUE(bridge.refuse_host("attacker.example:8765"));
  EXPECT_TRUE(bridge.refuse("", ""));  // no Host at all (HTTP/1.1 requires one)
  EXPECT_TRUE(bridge.refuse("127.0.0.1:87x", ""));
  EXPECT_TRUE(bridge.refuse("local host:8765", ""));
  EXPECT_EQ(bridge.refuse_host("localhost:8765"), std::nullopt);
}

TEST(OriginPolicy, ParsesHostsAndOriginsAuthorities) {
  EXPECT_EQ(parse_authority("LocalHost:8765")->name, "localhost");
  EXPECT_EQ(parse_authority("LocalHost:8765")->port, 8765);
  EXPECT_EQ(parse_authority("[::1]:80")->name, "::1");
  EXPECT_EQ(parse_authority("example")->port, std::nullopt);
  EXPECT_FALSE(parse_authority("[::1"));
  EXPECT_FALSE(parse_authority(":8765"));
  EXPECT_FALSE(parse_authority("host:65536"));
  EXPECT_FALSE(parse_authority("host:"));
}

TEST(OriginPolicy, AServerOnEveryInterfaceAnswersToThisMachinesAddresses) {
  const std::vector<std::string> loopback_only = own_host_names("127.0.0.1");
  EXPECT_NE(std::find(loopback_only.begin(), loopback_only.end(), "localhost"),
            loopback_only.end());
  const std::vector<std::string> everywhere = own_host_names("0.0.0.0");
  // Every name of the loopback-only server, and at least the loopback interface's address.
  for (const std::string& name : loopback_only) {
    EXPECT_NE(std::find(everywhere.begin(), everywhere.end(), name), everywhere.end()) << name;
  }
  EXPECT_EQ(std::find(everywhere.begin(), everywhere.end(), "0.0.0.0"), everywhere.end());
}

}  // namespace
}  // namespace mocap::foxglove
