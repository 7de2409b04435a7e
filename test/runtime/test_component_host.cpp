// Components in one process: declared topics, parameters, zero-copy delivery, timers,
// errors and shutdown, through the same ComponentHost that mocap_launch uses.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <mutex>
#include <set>
#include <thread>

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/fiducial.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "core/names.hpp"
#include "dds/dds_transport.hpp"
#include "host/dds_implementations.hpp"
#include "test/plugins/sequence_message.hpp"
#include "test/test_support.hpp"

namespace mocap {
namespace {

using Array = mocap_msgs::msg::FiducialArray;

HostOptions in_process() { return {.name = "test", .threads = 2, .dds = {.enabled = false}}; }

// What the test components saw; reset by each test.
struct Record {
  std::mutex mutex;
  std::vector<const void*> published;
  std::vector<const void*> received;
  std::atomic<int> ticks{0};
  std::atomic<int> active{0};
  std::atomic<int> max_active{0};
  void clear() {
    published.clear();
    received.clear();
    ticks = active = max_active = 0;
  }
} record;

// The one-parameter settings of the test components below.
struct Count {
  int count = 50;
};
struct Expect {
  int expect = 50;
};
const ParameterList<Count> kCount =
    ParameterList<Count>().add("count", "messages to publish", &Count::count).min(1);
const ParameterList<Expect> kExpect =
    ParameterList<Expect>().add("expect", "messages before shutdown", &Expect::expect).min(1);

class Source final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    kCount.declare(spec);
    spec.publishes<Array>("/numbers", Qos::reliable(), "");
  }
  explicit Source(Context& context) : Component(context) {
    publisher_ = create_publisher<Array>("/numbers");
    create_timer(std::chrono::milliseconds(1), [this, count = read_settings(kCount).count] {
      if (publisher_.matched_subscribers() == 0 || sent_ == count) return;
      auto message = std::make_shared<Array>();
      message->header().stamp().sec(sent_++);
      {
        std::lock_guard lock(record.mutex);
        record.published.push_back(message.get());
      }
      publisher_.publish(std::move(message));
    });
  }

 private:
  Publisher<Array> publisher_;
  int sent_ = 0;
};

class Sink final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    kExpect.declare(spec);
    spec.subscribes<Array>("/numbers", Qos::reliable(), "");
  }
  explicit Sink(Context& context) : Component(context) {
    create_subscription<Array>("/numbers", [this, expect = read_settings(kExpect).expect](
                                               const std::shared_ptr<const Array>& m) {
      std::lock_guard lock(record.mutex);
      record.received.push_back(m.get());
      if (static_cast<int>(record.received.size()) == expect) request_shutdown(0);
    });
  }
};

constexpr ComponentFactory kSource = make_component_factory<Source>("source");
constexpr ComponentFactory kSink = make_component_factory<Sink>("sink");

class ComponentHostTest : public ::testing::Test {
 protected:
  void SetUp() override { record.clear(); }
};

TEST_F(ComponentHostTest, InProcessDeliveryIsByPointer) {
  ComponentHost host(in_process());
  host.add(kSource, {.name = "source"});
  host.add(kSink, {.name = "sink"});
  EXPECT_EQ(host.run(std::chrono::seconds(30)), 0);
  ASSERT_EQ(record.received.size(), 50u);
  EXPECT_EQ(record.received, record.published);
}

TEST_F(ComponentHostTest, RemapsConnectTopics) {
  ComponentHost host(in_process());
  host.add(kSource, {.name = "source", .remaps = {{"/numbers", "/renamed"}}});
  host.add(kSink, {.name = "unconnected", .parameters = {{"expect", int64_t{1}}}});
  host.add(kSink, {.name = "sink", .remaps = {{"/numbers", "/renamed"}}});
  EXPECT_EQ(host.run(std::chrono::seconds(30)), 0);
  EXPECT_EQ(record.received.size(), 50u);  // all from "sink"
}

struct Camera {
  std::string camera = "left";
};
const ParameterList<Camera> kCamera =
    ParameterList<Camera>().add("camera", "which topic of the family", &Camera::camera);

// Publishes on one topic of the family /cameras/{camera}/numbers, chosen by a parameter.
class FamilySource final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    kCamera.declare(spec);
    spec.publishes<Array>("/cameras/{camera}/numbers", Qos::reliable(), "");
  }
  explicit FamilySource(Context& context) : Component(context) {
    publisher_ = create_publisher<Array>("/cameras/" + read_settings(kCamera).camera + "/numbers");
    create_timer(std::chrono::milliseconds(1), [this] {
      if (publisher_.matched_subscribers() == 0 || sent_ == 50) return;
      auto message = std::make_shared<Array>();
      message->header().frame_id(publisher_.topic());
      ++sent_;
      publisher_.publish(std::move(message));
    });
  }

 private:
  Publisher<Array> publisher_;
  int sent_ = 0;
};

TEST_F(ComponentHostTest, TopicFamiliesAreInstantiatedAndRemappedByTheirPlaceholders) {
  ComponentHost host(in_process());
  // The family remapped with its placeholder: the source's /cameras/right/numbers becomes
  // /right/numbers, where the sink reads.
  host.add(make_component_factory<FamilySource>("family_source"),
           {.name = "right",
            .parameters = {{"camera", std::string("right")}},
            .remaps = {{"/cameras/{camera}/numbers", "/{camera}/numbers"}}});
  host.add(kSink, {.name = "sink", .remaps = {{"/numbers", "/right/numbers"}}});
  EXPECT_EQ(host.run(std::chrono::seconds(30)), 0);
  EXPECT_EQ(record.received.size(), 50u);
}

// Relays every known topic published by someone else to /relayed/<last segment>, with the
// type the deployment declares: a recorder's and a player's use of any-topic declarations.
class AnyRelay final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes_any("every published topic");
    spec.publishes_any("their copies");
  }
  explicit AnyRelay(Context& context) : Component(context) {
    for (const KnownTopic& topic : context.known_topics()) {
      if (topic.publishers.empty() || topic.topic.starts_with("/relayed")) continue;
      auto out = context.advertise_any("/relayed" + topic.topic.substr(topic.topic.rfind('/')),
                                       *topic.type, topic.publishers.front());
      context.subscribe_any(topic.topic, *topic.type, topic.publishers.front(),
                            [out](const std::shared_ptr<const void>& m) { out->publish(m); });
    }
  }
};

TEST_F(ComponentHostTest, AnyTopicComponentsUseTheDeploymentsTypesAndRemaps) {
  ComponentHost host(in_process());
  host.add(kSource, {.name = "source"});
  // The relay's /relayed/numbers is remapped like any declared topic.
  host.add(make_component_factory<AnyRelay>("any_relay"),
           {.name = "relay", .remaps = {{"/relayed/numbers", "/copies"}}});
  host.add(kSink, {.name = "sink", .remaps = {{"/numbers", "/copies"}}});
  EXPECT_EQ(host.run(std::chrono::seconds(30)), 0);
  ASSERT_EQ(record.received.size(), 50u);
  EXPECT_EQ(record.received, record.published);  // relayed by pointer
}

TEST_F(ComponentHostTest, AnyTopicsAreTypeCheckedWhenUsed) {
  // A component that uses an any-topic with a type other than the one the topic carries.
  class WrongType final : public Component {
   public:
    static void declare(ComponentSpec& spec) { spec.publishes_any("anything"); }
    explicit WrongType(Context& context) : Component(context) {
      context.advertise_any("/numbers", message_type<mocap_msgs::msg::Fiducial>(), Qos::reliable());
    }
  };
  ComponentHost host(in_process());
  host.add(kSink, {.name = "sink"});
  try {
    host.add(make_component_factory<WrongType>("wrong_type"), {.name = "wrong"});
    ADD_FAILURE() << "no error";
  } catch (const ComponentError& e) {
    EXPECT_NE(std::string(e.what()).find("topic '/numbers' carries mocap_msgs/msg/FiducialArray"),
              std::string::npos)
        << e.what();
  }
  // Without an any-topic declaration, the any-topic calls are refused.
  class Undeclared final : public Component {
   public:
    static void declare(ComponentSpec&) {}
    explicit Undeclared(Context& context) : Component(context) {
      context.subscribe_any("/numbers", message_type<Array>(), Qos::reliable(),
                            [](const std::shared_ptr<const void>&) {});
    }
  };
  EXPECT_THROW(host.add(make_component_factory<Undeclared>("undeclared"), {.name = "undeclared"}),
               ComponentError);
}

TEST(TopicFamilies, NamesMatchSegmentBySegment) {
  EXPECT_EQ(match_topic_family("/pixart/{camera}/fiducials", "/pixart/cam_0/fiducials"),
            std::vector<std::string>{"cam_0"});
  EXPECT_FALSE(match_topic_family("/pixart/{camera}/fiducials", "/pixart/a/b/fiducials"));
  EXPECT_FALSE(match_topic_family("/pixart/{camera}/fiducials", "/pixart/cam0/raw"));
  EXPECT_EQ(instantiate_topic_family("/{a}/x/{b}", {"1", "2"}), "/1/x/2");
  EXPECT_TRUE(topics_overlap("/pixart/{camera}/fiducials", "/pixart/cam0/fiducials"));
  EXPECT_TRUE(topics_overlap("/pixart/{camera}/fiducials", "/pixart/{c}/fiducials"));
  EXPECT_FALSE(topics_overlap("/pixart/{camera}/fiducials", "/mocap/fiducials"));
  EXPECT_FALSE(topics_overlap("/a/b", "/a/c"));
  EXPECT_TRUE(valid_topic_family("/a/{b}/c"));
  EXPECT_FALSE(valid_topic_family("/a/{b}x/c"));
}

TEST(TopicFamilies, TopicsOfAFamilyMustMatchItAndRemapsKeepItsPlaceholders) {
  ComponentSpec spec;
  FamilySource::declare(spec);
  EXPECT_TRUE(
      check_component_config(
          spec, {.name = "s", .remaps = {{"/cameras/{camera}/numbers", "/{camera}/numbers"}}})
          .empty());
  auto problems = check_component_config(
      spec, {.name = "s", .remaps = {{"/cameras/{camera}/numbers", "/all/numbers"}}});
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("must be a topic family with 1 placeholder(s)"), std::string::npos)
      << problems[0];
  ComponentSpec bad;
  EXPECT_THROW(bad.publishes<Array>("/cameras/x{camera}/numbers", Qos::reliable(), ""),
               std::logic_error);
  // A topic outside the family is refused when the component asks for it.
  class Stray final : public Component {
   public:
    static void declare(ComponentSpec& s) { FamilySource::declare(s); }
    explicit Stray(Context& context) : Component(context) {
      create_publisher<Array>("/cameras/left/other");
    }
  };
  ComponentHost host(in_process());
  EXPECT_THROW(host.add(make_component_factory<Stray>("stray"), {.name = "stray"}), ComponentError);
}

TEST_F(ComponentHostTest, QosOverrideThatCannotMatchDeliversNothing) {
  ComponentHost host(in_process());
  host.add(kSource, {.name = "source", .qos = {{"/numbers", Qos::sensor_data()}}});
  host.add(kSink, {.name = "sink"});  // reliable: does not match best effort
  host.run(std::chrono::milliseconds(200));
  EXPECT_TRUE(record.received.empty());
}

class Latcher final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.publishes<Array>("/numbers", Qos::latched(), "");
  }
  explicit Latcher(Context& context) : Component(context) {
    auto message = std::make_shared<Array>();
    record.published.push_back(message.get());
    create_publisher<Array>("/numbers").publish(std::move(message));
  }
};

TEST_F(ComponentHostTest, LatchedSampleReachesALateComponentByPointer) {
  ComponentHost host(in_process());
  host.add(make_component_factory<Latcher>("latcher"), {.name = "latcher"});
  host.start();
  host.add(kSink, {.name = "late",
                   .parameters = {{"expect", int64_t{1}}},
                   .qos = {{"/numbers", Qos::latched()}}});
  EXPECT_EQ(host.run(std::chrono::seconds(30)), 0);
  ASSERT_EQ(record.received.size(), 1u);
  EXPECT_EQ(record.received[0], record.published[0]);
}

class Undeclared final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.publishes<Array>("/declared", Qos::reliable(), "");
  }
  explicit Undeclared(Context& context) : Component(context) {
    create_publisher<Array>("/undeclared");
  }
};

class Throwing final : public Component {
 public:
  static void declare(ComponentSpec&) {}
  explicit Throwing(Context& context) : Component(context) {
    throw std::runtime_error("cannot open /dev/ttyUSB9");
  }
};

TEST_F(ComponentHostTest, StartErrorsNameTheComponent) {
  ComponentHost host(in_process());
  try {
    host.add(make_component_factory<Undeclared>("undeclared"), {.name = "u"});
    FAIL();
  } catch (const ComponentError& e) {
    EXPECT_STREQ(e.what(),
                 "component 'u' (undeclared) failed to start: component 'u' publishes "
                 "to '/undeclared', which its declare() does not declare (declared: "
                 "/declared)");
  }
  try {
    host.add(make_component_factory<Throwing>("throwing"), {.name = "t"});
    FAIL();
  } catch (const ComponentError& e) {
    EXPECT_STREQ(e.what(), "component 't' (throwing) failed to start: cannot open /dev/ttyUSB9");
  }
}

TEST_F(ComponentHostTest, ConfigurationErrors) {
  ComponentHost host(in_process());
  host.add(kSink, {.name = "sink"});
  auto error_of = [&](ComponentConfig config) -> std::string {
    try {
      host.add(kSink, std::move(config));
    } catch (const ComponentError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error_of({.name = "sink"}), "component 'sink' (sink): the name is taken");
  EXPECT_EQ(error_of({.name = "a b"}),
            "component 'a b' (sink): names use letters, digits, '_' and '-'");
  EXPECT_EQ(error_of({.name = "other", .parameters = {{"expct", int64_t{2}}, {"expect", 0.5}}}),
            "component 'other' (sink): unknown parameter 'expct' (did you mean 'expect'?); "
            "parameter 'expect' expects int >= 1, got double 0.5");
  EXPECT_EQ(error_of({.name = "other", .remaps = {{"/numbers", "numbers"}}}),
            "component 'other' (sink): remap target 'numbers' is not a topic name (like /a/b_c)");
}

struct Fail {
  bool fail = false;
};
const ParameterList<Fail> kFail =
    ParameterList<Fail>().add("fail", "throw from every other tick", &Fail::fail);

class Ticker final : public Component {
 public:
  static void declare(ComponentSpec& spec) { kFail.declare(spec); }
  explicit Ticker(Context& context) : Component(context) {
    bool fail = read_settings(kFail).fail;
    for (int timer = 0; timer < 3; ++timer) {
      create_timer(std::chrono::microseconds(200), [this, fail] {
        // Callbacks of one component never overlap, however many threads there are.
        int now_active = ++record.active;
        int seen = record.max_active;
        while (now_active > seen && !record.max_active.compare_exchange_weak(seen, now_active)) {
        }
        std::this_thread::sleep_for(std::chrono::microseconds(50));
        --record.active;
        int tick = ++record.ticks;
        if (tick == 300) request_shutdown(7);
        if (fail && tick % 2 == 0) throw std::runtime_error("odd failure");
      });
    }
  }
};

TEST_F(ComponentHostTest, OneComponentsCallbacksNeverOverlapAndErrorsAreCounted) {
  ComponentHost host({.name = "test", .threads = 4, .dds = {.enabled = false}});
  host.add(make_component_factory<Ticker>("ticker"),
           {.name = "ticker", .parameters = {{"fail", true}}});
  EXPECT_EQ(host.run(std::chrono::seconds(60)), 7);  // the requested exit code
  EXPECT_GE(record.ticks, 300);
  EXPECT_EQ(record.max_active, 1);
  EXPECT_GE(host.callback_errors(), 150u);
}

// Back-pressure inside one process: publishes `count` messages in one callback, as fast as
// its subscribers let it, and keeps what it saw.
struct BurstRecord {
  std::atomic<bool> done{false};
  std::atomic<int> ticks_during{0};  // the ticker's ticks while the burst was publishing
  PublisherStats stats;
  std::vector<int> received;
  std::mutex mutex;
} burst;

struct BurstCount {
  int count = 500;
};
struct BurstExpect {
  int expect = 500;
};
const ParameterList<BurstCount> kBurstCount =
    ParameterList<BurstCount>().add("count", "messages in the burst", &BurstCount::count).min(1);
const ParameterList<BurstExpect> kBurstExpect =
    ParameterList<BurstExpect>()
        .add("expect", "messages before shutdown", &BurstExpect::expect)
        .min(1);

class Burst final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    kBurstCount.declare(spec);
    spec.publishes<Array>("/burst", Qos::reliable(), "");
  }
  explicit Burst(Context& context) : Component(context) {
    publisher_ = create_publisher<Array>("/burst");
    create_timer(std::chrono::milliseconds(1), [this] {
      if (sent_ || publisher_.matched_subscribers() == 0) return;
      sent_ = true;
      int ticks_before = record.ticks;
      for (int i = 0; i < count_; ++i) {
        Array message;
        message.header().stamp().sec(i);
        publisher_.publish(std::move(message));
      }
      burst.ticks_during = record.ticks - ticks_before;
      burst.stats = publisher_.stats();
      burst.done = true;
    });
  }

 private:
  Publisher<Array> publisher_;
  const int count_ = read_settings(kBurstCount).count;
  bool sent_ = false;
};

class SlowSink final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    kBurstExpect.declare(spec);
    spec.subscribes<Array>("/burst", Qos::reliable(), "");
  }
  explicit SlowSink(Context& context) : Component(context) {
    create_subscription<Array>(
        "/burst", [this, expect = read_settings(kBurstExpect).expect](const Array& message) {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
          std::lock_guard lock(burst.mutex);
          burst.received.push_back(message.header().stamp().sec());
          if (static_cast<int>(burst.received.size()) == expect) request_shutdown(0);
        });
  }
};

class Counter final : public Component {
 public:
  static void declare(ComponentSpec&) {}
  explicit Counter(Context& context) : Component(context) {
    create_timer(std::chrono::milliseconds(2), [] { ++record.ticks; });
  }
};

Qos reliable_with_depth(int depth) {
  Qos qos = Qos::reliable();
  qos.depth = depth;
  return qos;
}

TEST_F(ComponentHostTest, ASlowSubscriberHoldsItsPublisherBackWhileTheOthersRunOn) {
  burst.received.clear();
  burst.done = false;
  // One executor thread: the publisher waiting inside its callback must lend it, or neither
  // the subscriber it waits for nor anyone else would run.
  ComponentHost host({.name = "test", .threads = 1, .dds = {.enabled = false}});
  host.add(make_component_factory<Burst>("burst"),
           {.name = "burst", .qos = {{"/burst", reliable_with_depth(10)}}});
  host.add(make_component_factory<SlowSink>("slow_sink"),
           {.name = "sink", .qos = {{"/burst", reliable_with_depth(10)}}});
  host.add(make_component_factory<Counter>("counter"), {.name = "counter"});
  EXPECT_EQ(host.run(std::chrono::seconds(60)), 0);
  ASSERT_TRUE(burst.done);
  ASSERT_EQ(burst.received.size(), 500u);
  for (int i = 0; i < 500; ++i) ASSERT_EQ(burst.received[static_cast<size_t>(i)], i);
  EXPECT_EQ(burst.stats.published, 500u);
  EXPECT_EQ(burst.stats.dropped, 0u);
  EXPECT_GT(burst.stats.waited, 0u);
  EXPECT_GT(burst.stats.blocked, std::chrono::milliseconds(100));  // of about 500 ms of work
  EXPECT_GT(burst.ticks_during, 0);  // the other component ran on meanwhile
}

TEST_F(ComponentHostTest, StoppingReleasesAPublisherWaitingForASubscriber) {
  burst.received.clear();
  burst.done = false;
  ComponentHost host({.name = "test", .threads = 2, .dds = {.enabled = false}});
  host.add(make_component_factory<Burst>("burst"), {.name = "burst",
                                                    .parameters = {{"count", int64_t{100000}}},
                                                    .qos = {{"/burst", reliable_with_depth(10)}}});
  host.add(make_component_factory<SlowSink>("slow_sink"),
           {.name = "sink",
            .parameters = {{"expect", int64_t{100000}}},
            .qos = {{"/burst", reliable_with_depth(10)}}});
  // 100 s of work for the sink; the host must still stop when asked.
  auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(host.run(std::chrono::milliseconds(300)), 0);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
  ASSERT_TRUE(burst.done);
  EXPECT_EQ(burst.stats.published, 100000u);
  EXPECT_GT(burst.stats.dropped, 90000u);  // given up once stopping: nobody would take them
  std::lock_guard lock(burst.mutex);
  EXPECT_LE(burst.received.size() + burst.stats.dropped, 100000u);
  EXPECT_TRUE(std::is_sorted(burst.received.begin(), burst.received.end()));
  EXPECT_EQ(std::adjacent_find(burst.received.begin(), burst.received.end()),
            burst.received.end());  // none twice
}

// Subscribes to the test sequence of another process and, from its callbacks, once they have
// shown to be quick (so that a DDS receive thread could run them), subscribes to it once more.
// Fast DDS attaches a new reader to its receive resources under a lock its receive thread
// holds while delivering: created on that thread, the reader would never come.
class SubscribesInItsCallbacks final : public Component {
 public:
  static void declare(ComponentSpec& spec) { spec.subscribes_any("the test sequence, twice"); }
  explicit SubscribesInItsCallbacks(Context& context) : Component(context) {
    context.subscribe_any(test::kSequenceTopic, message_type<Array>(), Qos::reliable(),
                          [this](const std::shared_ptr<const void>&) {
                            if (++first_ != 200) return;
                            this->context().subscribe_any(
                                test::kSequenceTopic, message_type<Array>(), Qos::reliable(),
                                [](const std::shared_ptr<const void>&) { ++second; });
                          });
  }
  static inline std::atomic<int> second{0};

 private:
  int first_ = 0;
};

// Another process publishing the test sequence endlessly (1,000 a second) on the DDS domain
// of `slot`, which this process then uses too.
std::unique_ptr<test::ChildProcess> sequence_process(const test::TempDir& dir, int slot) {
  const std::string domain = std::to_string(test::test_domain(slot));
  setenv("MOCAP_DOMAIN_ID", domain.c_str(), 1);
  test::write_file(dir / "source.yaml", R"(groups:
  - name: source
    components:
      - plugin: sequence_source
        name: source
        parameters: {count: 0, batch: 5, period_s: 0.005, subscribers: 1}
)");
  return std::make_unique<test::ChildProcess>(
      std::vector<std::string>{(test::bin_dir() / "mocap_launch").string(),
                               (dir / "source.yaml").string()},
      std::map<std::string, std::string>{{"MOCAP_DOMAIN_ID", domain},
                                         {"MOCAP_PLUGIN_PATH", test::test_plugin_dir().string()}},
      dir / "source.log");
}

TEST(ComponentHostOverDds, AComponentSubscribingInItsCallbacksKeepsReceiving) {
  test::TempDir dir;
  const auto source = sequence_process(dir, 86);
  ComponentHost host({.name = "late_subscriber", .threads = 2, .dds = {.enabled = true}});
  host.add(make_component_factory<SubscribesInItsCallbacks>("subscribes_in_callbacks"),
           {.name = "subscriber"});
  host.start();
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (SubscribesInItsCallbacks::second < 100 && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_GE(SubscribesInItsCallbacks::second, 100) << source->output();
  host.stop();
}

// Takes 100 of another process's test sequence, lets go of it from the 100th callback, waits
// 0.3 s, and subscribes again: nothing arrives in between, the stream comes back after.
class UnsubscribesInItsCallbacks final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.subscribes_any("the test sequence, let go of and taken again");
  }
  explicit UnsubscribesInItsCallbacks(Context& context) : Component(context) {
    subscribe([this] {
      if (++first != 100) return;
      this->context().unsubscribe_any(test::kSequenceTopic);
      let_go = Clock::now();
    });
    create_timer(std::chrono::milliseconds(20), [this] {
      if (let_go && !again && Clock::now() - *let_go > std::chrono::milliseconds(300)) {
        first_when_taken_again = first.load();
        again = true;
        subscribe([] { ++second; });
      }
    });
  }
  static inline std::atomic<int> first{0}, second{0}, first_when_taken_again{-1};

 private:
  void subscribe(std::function<void()> on_message) {
    context().subscribe_any(test::kSequenceTopic, message_type<Array>(), Qos::reliable(),
                            [on_message](const std::shared_ptr<const void>&) { on_message(); });
  }
  std::optional<Clock::time_point> let_go;
  bool again = false;
};

TEST(ComponentHostOverDds, AComponentLetsGoOfATopicAndTakesItAgain) {
  test::TempDir dir;
  const auto source = sequence_process(dir, 85);
  ComponentHost host({.name = "unsubscriber", .threads = 2, .dds = {.enabled = true}});
  host.add(make_component_factory<UnsubscribesInItsCallbacks>("unsubscribes"),
           {.name = "unsubscriber"});
  host.start();
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (UnsubscribesInItsCallbacks::second < 100 && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  host.stop();
  EXPECT_EQ(UnsubscribesInItsCallbacks::first_when_taken_again, 100) << "none after letting go";
  EXPECT_EQ(UnsubscribesInItsCallbacks::first, 100);
  EXPECT_GE(UnsubscribesInItsCallbacks::second, 100) << source->output();
}

// The lifecycle as components see it: what happened, in order.
struct Lifecycle {
  std::mutex mutex;
  std::vector<std::string> events;
  void add(std::string event) {
    std::lock_guard lock(mutex);
    events.push_back(std::move(event));
  }
  std::vector<std::string> list() {
    std::lock_guard lock(mutex);
    return events;
  }
  void clear() {
    std::lock_guard lock(mutex);
    events.clear();
  }
} lifecycle;

// A worker that blocks in a read (a pipe nobody writes) with a 20 ms timeout, as a serial or
// CAN reader does; it ends when asked to stop.
class Reader final : public Component {
 public:
  static void declare(ComponentSpec&) {}
  explicit Reader(Context& context) : Component(context) {
    if (pipe(fds_) != 0) throw std::runtime_error("pipe");
    lifecycle.add(name() + " constructed");
    create_worker("read", [this](std::stop_token stop) {
      lifecycle.add(name() + " worker started");
      char byte;
      while (!stop.stop_requested()) {
        pollfd fd{fds_[0], POLLIN, 0};
        if (poll(&fd, 1, 20) > 0 && read(fds_[0], &byte, 1) == 1) lifecycle.add("read");
      }
      lifecycle.add(name() + " worker stopped");
    });
  }
  ~Reader() override {
    lifecycle.add(name() + " destroyed");
    close(fds_[0]);
    close(fds_[1]);
  }

 private:
  int fds_[2] = {-1, -1};
};

// A one-shot timer beside a periodic one, which ends the run at its fifth tick.
class OneShot final : public Component {
 public:
  static void declare(ComponentSpec&) {}
  explicit OneShot(Context& context) : Component(context) {
    create_one_shot_timer(std::chrono::milliseconds(1), [] { lifecycle.add("one shot"); });
    create_timer(std::chrono::milliseconds(20), [this] {
      if (++ticks_ == 5) request_shutdown(0);
    });
  }

 private:
  int ticks_ = 0;
};

// A worker that fails at once.
class Failing final : public Component {
 public:
  static void declare(ComponentSpec&) {}
  explicit Failing(Context& context) : Component(context) {
    create_worker("fail", [](std::stop_token) { throw std::runtime_error("no device"); });
  }
};

TEST(Lifecycle, WorkersRunBetweenTheConstructorsAndTheDestructorsAndStopWhenAsked) {
  lifecycle.clear();
  {
    ComponentHost host(in_process());
    host.add(make_component_factory<Reader>("reader"), {.name = "first"});
    host.add(make_component_factory<Reader>("reader"), {.name = "second"});
    host.add(make_component_factory<Failing>("failing"), {.name = "failing"});
    host.add(make_component_factory<OneShot>("one_shot"), {.name = "one_shot"});
    // Nothing runs before the host starts, however long construction takes.
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    EXPECT_EQ(lifecycle.list(),
              (std::vector<std::string>{"first constructed", "second constructed"}));
    EXPECT_EQ(host.run(), 0);               // until the fifth tick
    EXPECT_EQ(host.callback_errors(), 1u);  // the failing worker, counted; the others ran on
  }
  const std::vector<std::string> events = lifecycle.list();
  auto at = [&](const std::string& event) {
    auto found = std::find(events.begin(), events.end(), event);
    EXPECT_NE(found, events.end()) << event;
    return found - events.begin();
  };
  for (const char* component : {"first", "second"}) {
    const std::string name(component);
    EXPECT_GT(at(name + " worker started"), at("second constructed")) << name;
    // Blocked in a read, the worker saw the stop within its timeout, before any destructor.
    EXPECT_LT(at(name + " worker stopped"), at("first destroyed")) << name;
    EXPECT_LT(at(name + " worker stopped"), at("second destroyed")) << name;
  }
  EXPECT_EQ(std::count(events.begin(), events.end(), "one shot"), 1);  // not again in 100 ms
  EXPECT_EQ(std::count(events.begin(), events.end(), "read"), 0);
}

}  // namespace
}  // namespace mocap

namespace mocap {
namespace {

TEST(DomainId, TheEnvironmentOverridesTheLaunchFile) {
  unsetenv("MOCAP_DOMAIN_ID");
  EXPECT_EQ(resolve_domain_id(7), 7);
  setenv("MOCAP_DOMAIN_ID", "42", 1);
  EXPECT_EQ(resolve_domain_id(7), 42);
  for (const char* bad : {"233", "-1", "4x", "many"}) {
    setenv("MOCAP_DOMAIN_ID", bad, 1);
    try {
      resolve_domain_id(7);
      ADD_FAILURE() << bad;
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), fmt::format("MOCAP_DOMAIN_ID='{}' is not a DDS domain id "
                                                   "(an integer 0..232)",
                                                   bad));
    }
  }
  unsetenv("MOCAP_DOMAIN_ID");
}

// The launch file's choice wins; MOCAP_DDS_IMPLEMENTATION is the default; Fast DDS without
// either. An unknown name says where it came from and what there is.
TEST(DdsImplementation, TheLaunchFileThenTheEnvironmentThenFastDds) {
  const char* saved = std::getenv("MOCAP_DDS_IMPLEMENTATION");
  std::string restore = saved != nullptr ? saved : "";
  unsetenv("MOCAP_DDS_IMPLEMENTATION");
  EXPECT_EQ(resolve_dds_implementation("").name, "fastdds");
  EXPECT_EQ(resolve_dds_implementation("cyclonedds").name, "cyclonedds");
  setenv("MOCAP_DDS_IMPLEMENTATION", "cyclonedds", 1);
  EXPECT_EQ(resolve_dds_implementation("").name, "cyclonedds");
  EXPECT_EQ(resolve_dds_implementation("fastdds").name, "fastdds");
  setenv("MOCAP_DDS_IMPLEMENTATION", "connext", 1);
  try {
    resolve_dds_implementation("");
    ADD_FAILURE() << "connext accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "MOCAP_DDS_IMPLEMENTATION 'connext' is not a DDS implementation here (available: " +
                  dds_implementation_names() + ")");
  }
  // A host on an unknown implementation does not start.
  EXPECT_THROW(ComponentHost({.name = "bad", .dds = {.implementation = "opendds"}}),
               std::runtime_error);
  if (restore.empty()) {
    unsetenv("MOCAP_DDS_IMPLEMENTATION");
  } else {
    setenv("MOCAP_DDS_IMPLEMENTATION", restore.c_str(), 1);
  }
}

// The health file: written when the host starts, and again every second while the executor
// runs callbacks (a HEALTHCHECK compares its age; here, a removed file comes back).
TEST(ComponentHostHealth, TheHealthFileIsRewrittenWhileTheHostRuns) {
  test::TempDir dir;
  std::filesystem::path file = dir / "health";
  HostOptions options = in_process();
  options.health_file = file.string();
  ComponentHost host(options);
  auto before = std::chrono::system_clock::now();
  host.start();
  ASSERT_TRUE(std::filesystem::exists(file));
  std::string text = test::read_file(file);
  long long seconds = 0;
  ASSERT_EQ(std::sscanf(text.c_str(), "test alive at %lld", &seconds), 1) << text;
  EXPECT_GE(seconds,
            std::chrono::duration_cast<std::chrono::seconds>(before.time_since_epoch()).count());
  std::filesystem::remove(file);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!std::filesystem::exists(file) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_TRUE(std::filesystem::exists(file)) << "not rewritten within 30 s";
  host.stop();
  // Stopped: no more rewriting, and no partial file left behind.
  std::filesystem::remove(file);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_FALSE(std::filesystem::exists(file));
  EXPECT_FALSE(std::filesystem::exists(dir / "health.partial"));
}

TEST(ComponentHostHealth, AHealthFileThatCannotBeWrittenStopsTheStart) {
  test::TempDir dir;
  HostOptions options = in_process();
  std::string file = (dir / "no_such_folder" / "health").string();
  options.health_file = file;
  ComponentHost host(options);
  try {
    host.start();
    FAIL() << "started without its health file";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cannot write the health file " + file + ": cannot write " + file + ".partial");
  }
}

// Health (mocap/health.hpp): each component's report_health() runs once a second on its own
// strand, never beside its callbacks, and process_health() gives every component of the process
// with the runtime's counts of its topics.
struct HealthRecord {
  std::atomic<bool> in_callback{false};
  std::atomic<int> overlaps{0};
  std::atomic<int> reports{0};
  std::mutex mutex;
  std::vector<ComponentHealth> seen;
} health_record;

class Reporter final : public Component {
 public:
  static void declare(ComponentSpec&) {}
  explicit Reporter(Context& context) : Component(context) {
    create_timer(std::chrono::microseconds(300), [this] {
      health_record.in_callback = true;
      std::this_thread::sleep_for(std::chrono::microseconds(50));
      ++ticks_;
      health_record.in_callback = false;
    });
  }
  void report_health(HealthReport& report) override {
    if (health_record.in_callback) ++health_record.overlaps;
    ++health_record.reports;
    report.add("ticks", std::to_string(ticks_));
    report.flag(HealthLevel::warn, "a test's warning");
  }

 private:
  int ticks_ = 0;
};

class HealthWatcher final : public Component {
 public:
  static void declare(ComponentSpec&) {}
  explicit HealthWatcher(Context& context) : Component(context) {
    create_timer(std::chrono::milliseconds(2500), [this] {
      std::lock_guard lock(health_record.mutex);
      health_record.seen = this->context().process_health();
      request_shutdown(0);
    });
  }
};

TEST_F(ComponentHostTest, EachComponentReportsItsHealthOnItsStrandWithTheRuntimesCounts) {
  ComponentHost host({.name = "healthy", .threads = 4, .dds = {.enabled = false}});
  host.add(kSource, {.name = "source"});
  host.add(kSink, {.name = "sink", .parameters = {{"expect", int64_t{1000}}}});
  host.add(make_component_factory<Reporter>("reporter"), {.name = "reporter"});
  host.add(make_component_factory<HealthWatcher>("watcher"), {.name = "watcher"});
  EXPECT_EQ(host.run(std::chrono::seconds(30)), 0);
  EXPECT_EQ(health_record.overlaps, 0);
  EXPECT_GE(health_record.reports, 2);
  std::lock_guard lock(health_record.mutex);
  ASSERT_EQ(health_record.seen.size(), 4u);
  const ComponentHealth& source = health_record.seen[0];
  EXPECT_EQ(source.name, "source");
  EXPECT_EQ(source.plugin, "source");
  ASSERT_EQ(source.published.size(), 1u);
  EXPECT_EQ(source.published[0].topic, "/numbers");
  EXPECT_EQ(source.published[0].messages, 50u);
  const ComponentHealth& sink = health_record.seen[1];
  ASSERT_EQ(sink.received.size(), 1u);
  EXPECT_EQ(sink.received[0].messages, 50u);
  EXPECT_EQ(sink.received[0].dropped, 0u);
  EXPECT_EQ(sink.received[0].waiting, std::optional<size_t>(0));  // all taken
  const ComponentHealth& reporter = health_record.seen[2];
  EXPECT_EQ(reporter.report.level, HealthLevel::warn);
  EXPECT_EQ(reporter.report.message, "a test's warning");
  ASSERT_EQ(reporter.report.values.size(), 1u);
  EXPECT_EQ(reporter.report.values[0].first, "ticks");
  EXPECT_GT(std::stoi(reporter.report.values[0].second), 100);
  EXPECT_NE(reporter.reported_at, std::chrono::steady_clock::time_point{});
}

}  // namespace
}  // namespace mocap
