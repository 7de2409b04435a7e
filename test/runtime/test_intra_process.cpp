// In-process delivery: pointers, not copies, under the same QoS rules as DDS.
#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <thread>

#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "transport/intra_process_transport.hpp"

namespace mocap {
namespace {

using Array = mocap_msgs::msg::FiducialArray;

Endpoint endpoint(const std::string& topic, Qos qos,
                  const MessageType& type = message_type<Array>()) {
  return {topic, &type, qos, "test"};
}

// An endpoint of component `owner`: a publisher waits only for other components.
Endpoint endpoint_of(const std::string& owner, const std::string& topic, Qos qos) {
  return {topic, &message_type<Array>(), qos, owner};
}

Qos reliable_with_depth(int depth) {
  Qos qos = Qos::reliable();
  qos.depth = depth;
  return qos;
}

std::shared_ptr<const void> take(TransportSubscription& subscription) {
  ReceivedMessage received;
  return subscription.take(received) ? received.message : nullptr;
}

std::shared_ptr<const Array> numbered(int n) {
  auto message = std::make_shared<Array>();
  message->header().stamp().sec(n);
  return message;
}

int number(const std::shared_ptr<const void>& message) {
  return std::static_pointer_cast<const Array>(message)->header().stamp().sec();
}

// Runs `publish` on another thread; the future is ready when it returns.
std::future<void> publish_async(TransportPublisher& publisher, int n) {
  return std::async(std::launch::async,
                    [&publisher, n] { publisher.publish(numbered(n), Clock::now()); });
}

bool returns_soon(std::future<void>& done) {
  return done.wait_for(std::chrono::seconds(30)) == std::future_status::ready;
}

// True once the future has not returned for a while: a publisher is waiting.
bool still_waiting(std::future<void>& done) {
  return done.wait_for(std::chrono::milliseconds(100)) == std::future_status::timeout;
}

TEST(IntraProcess, SubscribersReceiveThePublishersPointer) {
  IntraProcessTransport transport;
  int notified = 0;
  auto publisher = transport.advertise(endpoint("/a", Qos::reliable()));
  auto first = transport.subscribe(endpoint("/a", Qos::reliable()), [&](bool may_run_callbacks) {
    EXPECT_FALSE(may_run_callbacks);  // publishing never runs subscriber code
    ++notified;
  });
  auto second =
      transport.subscribe(endpoint("/a", Qos::sensor_data()), [&](bool may_run_callbacks) {
        EXPECT_FALSE(may_run_callbacks);  // publishing never runs subscriber code
        ++notified;
      });
  EXPECT_EQ(publisher->matched_subscribers(), 2u);
  auto message = numbered(1);
  publisher->publish(message, Clock::now());
  EXPECT_EQ(notified, 2);
  EXPECT_EQ(take(*first).get(), message.get());
  EXPECT_EQ(take(*second).get(), message.get());
  EXPECT_EQ(take(*first), nullptr);
  EXPECT_EQ(message.use_count(), 1);  // nobody kept a copy
}

TEST(IntraProcess, OtherTopicsAreSeparate) {
  IntraProcessTransport transport;
  auto publisher = transport.advertise(endpoint("/a", Qos::reliable()));
  auto other = transport.subscribe(endpoint("/b", Qos::reliable()), [](bool) {});
  publisher->publish(numbered(1), Clock::now());
  EXPECT_EQ(take(*other), nullptr);
}

TEST(IntraProcess, ATopicHasOneType) {
  IntraProcessTransport transport;
  auto publisher = transport.advertise(endpoint("/a", Qos::reliable()));
  try {
    transport.subscribe(endpoint("/a", Qos::reliable(), message_type<sensor_msgs::msg::Image>()),
                        [](bool) {});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "topic '/a' carries mocap_msgs/msg/FiducialArray (as used by 'test'), but "
                 "'test' uses it with sensor_msgs/msg/Image");
  }
}

TEST(IntraProcess, ReliableSubscriberDoesNotMatchBestEffortPublisher) {
  IntraProcessTransport transport;
  auto best_effort = transport.advertise(endpoint("/a", Qos::sensor_data()));
  auto reliable_subscriber = transport.subscribe(endpoint("/a", Qos::reliable()), [](bool) {});
  auto best_effort_subscriber =
      transport.subscribe(endpoint("/a", Qos::sensor_data()), [](bool) {});
  EXPECT_EQ(best_effort->matched_subscribers(), 1u);
  best_effort->publish(numbered(1), Clock::now());
  EXPECT_EQ(take(*reliable_subscriber), nullptr);
  EXPECT_NE(take(*best_effort_subscriber), nullptr);
}

TEST(IntraProcess, KeepLastDropsTheOldest) {
  IntraProcessTransport transport;
  Qos qos = Qos::sensor_data();
  qos.depth = 2;
  auto publisher = transport.advertise(endpoint("/a", Qos::sensor_data()));
  auto subscription = transport.subscribe(endpoint("/a", qos), [](bool) {});
  for (int i = 0; i < 5; ++i) publisher->publish(numbered(i), Clock::now());
  EXPECT_EQ(number(take(*subscription)), 3);
  EXPECT_EQ(number(take(*subscription)), 4);
  EXPECT_EQ(take(*subscription), nullptr);
}

TEST(IntraProcess, ReliablePublisherWaitsForASubscriberThatKeepsUp) {
  IntraProcessTransport transport;
  auto publisher = transport.advertise(endpoint_of("source", "/a", reliable_with_depth(1)));
  auto subscription =
      transport.subscribe(endpoint_of("sink", "/a", reliable_with_depth(1)), [](bool) {});
  constexpr int kCount = 300;
  std::thread producer([&] {
    for (int i = 0; i < kCount; ++i) publisher->publish(numbered(i), Clock::now());
  });
  std::vector<int> received;
  while (received.size() < kCount) {
    if (auto message = take(*subscription)) received.push_back(number(message));
  }
  producer.join();
  for (int i = 0; i < kCount; ++i) ASSERT_EQ(received[static_cast<size_t>(i)], i);
  EXPECT_EQ(publisher->stats().dropped, 0u);
}

TEST(IntraProcess, ReliablePublisherWaitsForAStalledSubscriberAsLongAsItTakes) {
  IntraProcessTransport transport;
  auto publisher = transport.advertise(endpoint_of("source", "/a", reliable_with_depth(2)));
  auto subscription =
      transport.subscribe(endpoint_of("sink", "/a", reliable_with_depth(2)), [](bool) {});
  for (int i = 0; i < 2; ++i) publisher->publish(numbered(i), Clock::now());
  auto third = publish_async(*publisher, 2);
  ASSERT_TRUE(still_waiting(third));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // longer than any old limit
  ASSERT_TRUE(still_waiting(third));
  EXPECT_EQ(number(take(*subscription)), 0);
  ASSERT_TRUE(returns_soon(third));
  EXPECT_EQ(number(take(*subscription)), 1);
  EXPECT_EQ(number(take(*subscription)), 2);
  EXPECT_EQ(take(*subscription), nullptr);
  PublisherStats stats = publisher->stats();
  EXPECT_EQ(stats.waited, 1u);
  EXPECT_GE(stats.blocked, std::chrono::milliseconds(400));
  EXPECT_EQ(stats.longest_wait, stats.blocked);
  EXPECT_EQ(stats.dropped, 0u);
}

TEST(IntraProcess, MaxBlockingBoundsTheWaitAndCountsTheDrop) {
  IntraProcessTransport transport;
  Qos limited = reliable_with_depth(2);
  limited.max_blocking = std::chrono::milliseconds(50);
  auto publisher = transport.advertise(endpoint_of("source", "/a", limited));
  auto subscription =
      transport.subscribe(endpoint_of("sink", "/a", reliable_with_depth(2)), [](bool) {});
  for (int i = 0; i < 3; ++i) publisher->publish(numbered(i), Clock::now());  // the 3rd drops
  EXPECT_EQ(number(take(*subscription)), 0);
  EXPECT_EQ(number(take(*subscription)), 1);
  EXPECT_EQ(take(*subscription), nullptr);
  PublisherStats stats = publisher->stats();
  EXPECT_EQ(stats.dropped, 1u);
  EXPECT_EQ(stats.waited, 1u);
  EXPECT_GE(stats.blocked, std::chrono::milliseconds(50));
}

TEST(IntraProcess, ASubscriptionThatGoesAwayReleasesAWaitingPublisherAtOnce) {
  IntraProcessTransport transport;
  auto publisher = transport.advertise(endpoint_of("source", "/a", reliable_with_depth(1)));
  auto subscription =
      transport.subscribe(endpoint_of("sink", "/a", reliable_with_depth(1)), [](bool) {});
  publisher->publish(numbered(0), Clock::now());
  auto second = publish_async(*publisher, 1);
  ASSERT_TRUE(still_waiting(second));
  subscription.reset();
  EXPECT_TRUE(returns_soon(second));
  EXPECT_EQ(publisher->stats().dropped, 0u);  // nobody is left to lose it
}

TEST(IntraProcess, StopWaitingReleasesWaitingPublishersAndLaterOnesDoNotWait) {
  IntraProcessTransport transport;
  auto publisher = transport.advertise(endpoint_of("source", "/a", reliable_with_depth(1)));
  auto subscription =
      transport.subscribe(endpoint_of("sink", "/a", reliable_with_depth(1)), [](bool) {});
  publisher->publish(numbered(0), Clock::now());
  auto second = publish_async(*publisher, 1);
  ASSERT_TRUE(still_waiting(second));
  transport.stop_waiting();
  ASSERT_TRUE(returns_soon(second));
  publisher->publish(numbered(2), Clock::now());
  EXPECT_EQ(publisher->stats().dropped, 2u);
  EXPECT_EQ(number(take(*subscription)), 0);
  EXPECT_EQ(take(*subscription), nullptr);
}

TEST(IntraProcess, KeepLastOnEitherSideNeverWaits) {
  IntraProcessTransport transport;
  Qos keep_last = Qos::sensor_data();
  keep_last.reliability = Reliability::Reliable;
  keep_last.depth = 2;
  // A keep-last publisher overwrites, as a DDS writer does; a keep-last subscriber too.
  auto overwriting = transport.advertise(endpoint_of("source", "/a", keep_last));
  auto keep_all =
      transport.subscribe(endpoint_of("sink", "/a", reliable_with_depth(2)), [](bool) {});
  auto publisher = transport.advertise(endpoint_of("source", "/b", reliable_with_depth(2)));
  auto keeps_last = transport.subscribe(endpoint_of("sink", "/b", keep_last), [](bool) {});
  for (int i = 0; i < 5; ++i) {
    overwriting->publish(numbered(i), Clock::now());
    publisher->publish(numbered(i), Clock::now());
  }
  for (auto* subscription : {keep_all.get(), keeps_last.get()}) {
    EXPECT_EQ(number(take(*subscription)), 3);
    EXPECT_EQ(number(take(*subscription)), 4);
  }
  EXPECT_EQ(publisher->stats().waited, 0u);
}

TEST(IntraProcess, AWaitThatCouldNeverEndTakesTheSampleBeyondTheDepthInstead) {
  IntraProcessTransport transport;
  // A component subscribed to its own output: waiting for itself would never end.
  auto own = transport.advertise(endpoint_of("loop", "/self", reliable_with_depth(1)));
  auto own_input =
      transport.subscribe(endpoint_of("loop", "/self", reliable_with_depth(1)), [](bool) {});
  for (int i = 0; i < 3; ++i) own->publish(numbered(i), Clock::now());
  for (int i = 0; i < 3; ++i) EXPECT_EQ(number(take(*own_input)), i);

  // Two components feeding each other: a waits for b's room while b waits for a's.
  auto a_out = transport.advertise(endpoint_of("a", "/to_b", reliable_with_depth(1)));
  auto b_in = transport.subscribe(endpoint_of("b", "/to_b", reliable_with_depth(1)), [](bool) {});
  auto b_out = transport.advertise(endpoint_of("b", "/to_a", reliable_with_depth(1)));
  auto a_in = transport.subscribe(endpoint_of("a", "/to_a", reliable_with_depth(1)), [](bool) {});
  a_out->publish(numbered(0), Clock::now());
  b_out->publish(numbered(0), Clock::now());
  auto a_waits = publish_async(*a_out, 1);
  ASSERT_TRUE(still_waiting(a_waits));
  b_out->publish(numbered(1), Clock::now());  // would close the cycle: goes beyond the depth
  EXPECT_EQ(number(take(*a_in)), 0);
  EXPECT_EQ(number(take(*a_in)), 1);
  EXPECT_EQ(number(take(*b_in)), 0);
  ASSERT_TRUE(returns_soon(a_waits));
  EXPECT_EQ(number(take(*b_in)), 1);
  EXPECT_EQ(a_out->stats().dropped + b_out->stats().dropped, 0u);
}

TEST(IntraProcess, LatchedSamplesReachLateSubscribersByPointer) {
  IntraProcessTransport transport;
  auto publisher = transport.advertise(endpoint("/map", Qos::latched()));
  auto old_message = numbered(1);
  auto last_message = numbered(2);
  publisher->publish(old_message, Clock::now());
  publisher->publish(last_message, Clock::now());
  int notified = 0;
  auto late = transport.subscribe(endpoint("/map", Qos::latched()), [&](bool may_run_callbacks) {
    EXPECT_FALSE(may_run_callbacks);  // publishing never runs subscriber code
    ++notified;
  });
  EXPECT_EQ(notified, 1);
  EXPECT_EQ(take(*late).get(), last_message.get());
  EXPECT_EQ(take(*late), nullptr);
  auto late_volatile = transport.subscribe(endpoint("/map", Qos::reliable()), [](bool) {});
  EXPECT_EQ(take(*late_volatile), nullptr);
  // A transient-local subscriber does not match a volatile publisher.
  auto volatile_publisher = transport.advertise(endpoint("/v", Qos::reliable()));
  auto wants_history = transport.subscribe(endpoint("/v", Qos::latched()), [](bool) {});
  EXPECT_EQ(volatile_publisher->matched_subscribers(), 0u);
}

TEST(IntraProcess, ALateJoinerTakesTheWholeHistoryWithoutAnyoneWaiting) {
  IntraProcessTransport transport;
  Qos history = reliable_with_depth(3);
  history.durability = Durability::TransientLocal;
  auto publisher = transport.advertise(endpoint_of("map", "/map", history));
  for (int i = 0; i < 5; ++i) publisher->publish(numbered(i), Clock::now());
  Qos small = reliable_with_depth(1);
  small.durability = Durability::TransientLocal;
  // Connecting happens under the transport's lock: the queue takes the publisher's history
  // beyond its own depth rather than making anyone wait there.
  auto late = transport.subscribe(endpoint_of("late", "/map", small), [](bool) {});
  for (int i = 2; i < 5; ++i) EXPECT_EQ(number(take(*late)), i);
  EXPECT_EQ(take(*late), nullptr);
  EXPECT_EQ(publisher->stats().waited, 0u);
}

TEST(IntraProcess, EndpointsLeaveCleanly) {
  IntraProcessTransport transport;
  auto publisher = transport.advertise(endpoint("/a", Qos::reliable()));
  {
    auto subscription = transport.subscribe(endpoint("/a", Qos::reliable()), [](bool) {});
    EXPECT_EQ(publisher->matched_subscribers(), 1u);
  }
  EXPECT_EQ(publisher->matched_subscribers(), 0u);
  publisher->publish(numbered(1), Clock::now());
}

}  // namespace
}  // namespace mocap
