// When the launcher starts a dead group again: a back-off that doubles, and a limit.
#include <gtest/gtest.h>

#include "launch/restart_policy.hpp"

namespace mocap {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

TEST(RestartPolicy, WaitsDoubleUntilTheGroupIsGivenUp) {
  RestartPolicy policy;  // 0.25 s first, 5 deaths within 60 s
  const RestartPolicy::Time start{};
  EXPECT_EQ(policy.on_death(start), milliseconds(250));
  EXPECT_EQ(policy.on_death(start + seconds(1)), milliseconds(500));
  EXPECT_EQ(policy.on_death(start + seconds(2)), milliseconds(1000));
  EXPECT_EQ(policy.on_death(start + seconds(4)), milliseconds(2000));
  EXPECT_EQ(policy.deaths_within_window(start + seconds(4)), 4);
  EXPECT_EQ(policy.on_death(start + seconds(59)), std::nullopt);  // the fifth within 60 s
}

TEST(RestartPolicy, DeathsOlderThanTheWindowAreForgotten) {
  RestartPolicy policy({.first_delay = milliseconds(100), .max_deaths = 3, .window = seconds(10)});
  const RestartPolicy::Time start{};
  EXPECT_EQ(policy.on_death(start), milliseconds(100));
  EXPECT_EQ(policy.on_death(start + seconds(5)), milliseconds(200));
  // The first has left the window: two within it, not three.
  EXPECT_EQ(policy.on_death(start + seconds(11)), milliseconds(200));
  EXPECT_EQ(policy.deaths_within_window(start + seconds(11)), 2);
  // Long quiet: back to the first wait.
  EXPECT_EQ(policy.on_death(start + seconds(100)), milliseconds(100));
}

}  // namespace
}  // namespace mocap
