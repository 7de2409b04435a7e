// In-process delivery: pointers, not copies, under the same QoS rules as DDS.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "intra_process_transport.hpp"

namespace mocap {
namespace {

using Array = mocap_msgs::msg::FiducialArray;

Endpoint endpoint(const std::string& topic, Qos qos,
                  const MessageType& type = message_type<Array>()) {
  return {topic, &type, qos, "test"};
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
  Qos qos = Qos::reliable();
  qos.depth = 1;
  auto publisher = transport.advertise(endpoint("/a", qos));
  auto subscription = transport.subscribe(endpoint("/a", qos), [](bool) {});
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
}

TEST(IntraProcess, ReliablePublisherGivesUpOnAStalledSubscriber) {
  IntraProcessTransport transport;
  Qos qos = Qos::reliable();
  qos.depth = 2;
  auto publisher = transport.advertise(endpoint("/a", qos));
  auto subscription = transport.subscribe(endpoint("/a", qos), [](bool) {});
  for (int i = 0; i < 3; ++i)
    publisher->publish(numbered(i), Clock::now());  // the 3rd waits, drops
  EXPECT_EQ(number(take(*subscription)), 0);
  EXPECT_EQ(number(take(*subscription)), 1);
  EXPECT_EQ(take(*subscription), nullptr);
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
