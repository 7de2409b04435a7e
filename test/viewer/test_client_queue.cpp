// A Foxglove client's queue (components/viewer/foxglove_bridge/client_queue.hpp): frames in
// order within the byte budget, the oldest dropped first and counted, and the verdict that a
// client stays too slow.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>

#include "viewer/foxglove_bridge/client_queue.hpp"

namespace mocap::foxglove {
namespace {

using namespace std::chrono_literals;
const ClientQueue::Clock::time_point t0{};

TEST(ClientQueue, KeepsFramesInOrderWithinItsBudget) {
  ClientQueue queue({.limit_bytes = 10});
  queue.push("aaa", t0);
  queue.push("bbb", t0);
  EXPECT_EQ(queue.bytes(), 6u);
  EXPECT_EQ(queue.pop(), "aaa");
  EXPECT_EQ(queue.pop(), "bbb");
  EXPECT_FALSE(queue.pop());
  EXPECT_EQ(queue.dropped(), 0u);
}

TEST(ClientQueue, DropsTheOldestFirstAndCountsThem) {
  ClientQueue queue({.limit_bytes = 10});
  queue.push("1111", t0);
  queue.push("2222", t0);
  queue.push("3333", t0);  // 12 bytes would not fit: "1111" goes
  EXPECT_EQ(queue.dropped(), 1u);
  EXPECT_EQ(queue.bytes(), 8u);
  EXPECT_EQ(queue.pop(), "2222");
  queue.push(std::string(11, 'x'), t0);  // larger than the budget on its own: itself dropped
  EXPECT_EQ(queue.dropped(), 2u);
  EXPECT_EQ(queue.pop(), "3333");
  EXPECT_FALSE(queue.pop());
}

TEST(ClientQueue, AClientBehindForTooLongIsToBeDisconnected) {
  ClientQueue queue({.limit_bytes = 4, .disconnect_after = 5s});
  queue.push("1234", t0);
  EXPECT_FALSE(queue.should_disconnect(t0 + 60s));  // never dropped
  queue.push("5678", t0 + 1s);                      // drops: behind since 1 s
  EXPECT_FALSE(queue.should_disconnect(t0 + 5s));
  queue.push("ab", t0 + 3s);  // drops again; behind since 1 s all the same
  EXPECT_TRUE(queue.should_disconnect(t0 + 6s));
  queue.push("c", t0 + 7s);  // fits, but the queue was never emptied: still behind
  EXPECT_TRUE(queue.should_disconnect(t0 + 7s));
  queue.pop();
  queue.pop();  // emptied: caught up
  EXPECT_FALSE(queue.should_disconnect(t0 + 60s));
}

// Options built in code get the checks the plugin's parameter range gives a launch file: the
// queue refuses them, naming the field.
TEST(ClientQueueOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(ClientQueueOptions{}.problem(), std::nullopt);
  EXPECT_EQ(ClientQueueOptions{.limit_bytes = 0}.problem(),
            "limit_bytes: 0 leaves no room for a message");
  EXPECT_EQ(ClientQueueOptions{.disconnect_after = -1500ms}.problem(),
            "disconnect_after: -1.5 s is below 0");
  EXPECT_EQ(ClientQueueOptions{.disconnect_after = 0s}.problem(), std::nullopt);  // at once
  try {
    ClientQueue queue({.limit_bytes = 0});
    ADD_FAILURE() << "a queue without room accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "ClientQueueOptions::limit_bytes: 0 leaves no room for a message");
  }
}

}  // namespace
}  // namespace mocap::foxglove
