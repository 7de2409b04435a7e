// A reliable stream into a subscriber that takes 5 ms over each message: the publisher,
// publishing as fast as it may, must wait for it and lose nothing. Per path: what arrived, the
// rate against the subscriber's own capacity, the time the publisher spent blocked in
// publish(), and the CPU time each process used. Reference: raw Fast DDS between two
// processes, with the runtime's QoS and with its stock keep-all settings (the whole depth in
// the writer's history, acknowledgements after 5 ms), measured in the same run.
//
//   build/bin/backpressure_bench [--quick]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <thread>

#include <fmt/format.h>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include <mocap_msgs/msg/FiducialArrayPubSubTypes.h>
#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

#include "core/names.hpp"
#include "dds/fastdds/fastdds_qos.hpp"
#include "dds/fastdds/fastdds_transport.hpp"

namespace {

namespace dds = eprosima::fastdds::dds;
using Array = mocap_msgs::msg::FiducialArray;
using Steady = std::chrono::steady_clock;

constexpr const char* kTopic = "/bench/backpressure";
constexpr auto kWork = std::chrono::milliseconds(5);

double seconds(Steady::duration d) { return std::chrono::duration<double>(d).count(); }

double cpu_seconds(const rusage& usage) {
  auto of = [](const timeval& t) { return double(t.tv_sec) + double(t.tv_usec) / 1e6; };
  return of(usage.ru_utime) + of(usage.ru_stime);
}

double own_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return cpu_seconds(usage);
}

Array numbered(int n) {
  Array message;
  message.header().frame_id("camera");
  message.header().stamp().sec(n);
  for (int i = 0; i < 12; ++i) {
    mocap_msgs::msg::Fiducial f;
    f.x(100.0f + float(i));
    f.y(200.0f - float(i));
    message.fiducials().push_back(f);
  }
  return message;
}

// What the subscriber saw: numbers in order, and the time its work took.
struct Seen {
  std::mutex mutex;
  std::condition_variable changed;
  int count = 0, in_order = 0, next = 0;
  Steady::duration work{};
  Steady::time_point last;

  void add(const Array& message) {
    auto start = Steady::now();
    std::this_thread::sleep_for(kWork);
    std::lock_guard lock(mutex);
    work += Steady::now() - start;
    if (message.header().stamp().sec() == next) ++in_order;
    next = message.header().stamp().sec() + 1;
    ++count;
    last = Steady::now();
    changed.notify_all();
  }
  bool wait_for(int total) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, std::chrono::seconds(600), [&] { return count >= total; });
  }
} seen;

// --- the runtime ------------------------------------------------------------------------

class Source final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
    spec.publishes<Array>(kTopic, mocap::Qos::reliable(), "");
  }
  explicit Source(mocap::Context& context) : Component(context) {
    publisher = create_publisher<Array>(kTopic);
  }
  mocap::Publisher<Array> publisher;
};

class SlowSink final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
    spec.subscribes<Array>(kTopic, mocap::Qos::reliable(), "");
  }
  explicit SlowSink(mocap::Context& context) : Component(context) {
    create_subscription<Array>(kTopic, [](const Array& message) { seen.add(message); });
  }
};

constexpr auto kSource = mocap::make_component_factory<Source>("source");
constexpr auto kSink = mocap::make_component_factory<SlowSink>("sink");

// --- raw Fast DDS -----------------------------------------------------------------------

// Fast DDS's own keep-all reliable settings: the depth in the writer's history as in the
// reader's, acknowledgements after its default 5 ms. The runtime used these before it kept
// only kWriterSamplesInFlight in the writer.
void stock_keep_all(dds::DataWriterQos& qos) {
  int depth = mocap::Qos::reliable().depth;
  qos.history().depth = depth;
  qos.resource_limits().max_samples = depth;
  qos.resource_limits().max_samples_per_instance = depth;
}
void stock_keep_all(dds::DataReaderQos& qos) {
  qos.reliable_reader_qos().times.heartbeatResponseDelay = {0, 5000000u};
}

class RawEndpoint : public dds::DataReaderListener, public dds::DataWriterListener {
 public:
  explicit RawEndpoint(bool stock) : stock_(stock) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    participant_ = factory->create_participant(mocap::resolve_domain_id(0),
                                               mocap::to_participant_qos({}, "raw"));
    dds::TypeSupport type(new mocap_msgs::msg::FiducialArrayPubSubType());
    type.register_type(participant_);
    topic_ = participant_->create_topic(mocap::dds_topic_name(kTopic), type.get_type_name(),
                                        dds::TOPIC_QOS_DEFAULT);
  }
  ~RawEndpoint() override {
    if (taker_.joinable()) {
      {
        std::lock_guard lock(mutex_);
        stopping_ = true;
      }
      data_.notify_all();
      taker_.join();
    }
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }

  void make_writer() {
    auto qos = mocap::to_writer_qos(mocap::Qos::reliable());
    if (stock_) stock_keep_all(qos);
    writer_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT)
                  ->create_datawriter(topic_, qos, this);
  }

  // Takes on a thread of its own, as a program doing slow work would, not on Fast DDS's.
  void make_reader() {
    auto qos = mocap::to_reader_qos(mocap::Qos::reliable());
    if (stock_) stock_keep_all(qos);
    reader_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT)
                  ->create_datareader(topic_, qos, this);
    taker_ = std::thread([this] {
      Array sample;
      dds::SampleInfo info;
      for (;;) {
        while (reader_->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
          if (info.valid_data) seen.add(sample);
        }
        std::unique_lock lock(mutex_);
        data_.wait_for(lock, std::chrono::milliseconds(10), [&] { return pending_ || stopping_; });
        if (stopping_) return;
        pending_ = false;
      }
    });
  }

  void on_data_available(dds::DataReader*) override {
    {
      std::lock_guard lock(mutex_);
      pending_ = true;
    }
    data_.notify_one();
  }
  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    matched = status.current_count;
  }

  // As the runtime does: write again while the history is full.
  void write(Array& message) {
    while (writer_->write(&message, dds::HANDLE_NIL) == ReturnCode_t::RETCODE_TIMEOUT) {
    }
  }

  std::atomic<int> matched{0};

 private:
  bool stock_;
  dds::DomainParticipant* participant_ = nullptr;
  dds::Topic* topic_ = nullptr;
  dds::DataWriter* writer_ = nullptr;
  dds::DataReader* reader_ = nullptr;
  std::thread taker_;
  std::mutex mutex_;
  std::condition_variable data_;
  bool pending_ = false, stopping_ = false;
};

// --- the subscriber process ------------------------------------------------------------

int run_subscriber(const std::string& path, int total, const std::string& out) {
  if (path == "runtime") {
    mocap::ComponentHost host({.name = "bench_subscriber", .threads = 2, .dds = {}});
    host.add(kSink, {.name = "sink"});
    host.start();
    seen.wait_for(total);
    host.stop();
  } else {
    RawEndpoint endpoint(path == "stock");
    endpoint.make_reader();
    seen.wait_for(total);
  }
  std::lock_guard lock(seen.mutex);
  std::ofstream(out) << seen.count << " " << seen.in_order << " "
                     << std::chrono::duration_cast<std::chrono::nanoseconds>(seen.work).count()
                     << "\n";
  return 0;
}

// --- the publisher's side ---------------------------------------------------------------

struct Row {
  std::string path;
  int delivered = 0, in_order = 0, expected = 0;
  double run_s = 0, work_s = 0, blocked_s = 0, publisher_cpu_s = 0, subscriber_cpu_s = -1;
};

// Publishes `count` messages as fast as `publish` returns; the time spent inside it.
template <class Publish>
double publish_all(int count, Publish publish) {
  Steady::duration inside{};
  for (int i = 0; i < count; ++i) {
    Array message = numbered(i);
    auto start = Steady::now();
    publish(std::move(message));
    inside += Steady::now() - start;
  }
  return seconds(inside);
}

Row run_in_process(int count) {
  {
    std::lock_guard lock(seen.mutex);
    seen.count = seen.in_order = seen.next = 0;
    seen.work = {};
  }
  Row row{.path = "in-process (runtime)", .expected = count};
  double cpu_before = own_cpu_seconds();
  mocap::ComponentHost host({.name = "bench", .threads = 2, .dds = {.enabled = false}});
  auto& source = static_cast<Source&>(host.add(kSource, {.name = "source"}));
  host.add(kSink, {.name = "sink"});
  host.start();
  auto start = Steady::now();
  publish_all(count, [&](Array message) { source.publisher.publish(std::move(message)); });
  seen.wait_for(count);
  row.run_s = seconds(seen.last - start);
  host.stop();
  row.blocked_s = seconds(source.publisher.stats().blocked);
  row.publisher_cpu_s = own_cpu_seconds() - cpu_before;  // both components: one process
  std::lock_guard lock(seen.mutex);
  row.delivered = seen.count;
  row.in_order = seen.in_order;
  row.work_s = seconds(seen.work);
  return row;
}

Row run_between_processes(const std::string& self, const std::string& path, int count) {
  static const std::map<std::string, std::string> labels = {
      {"runtime", "between processes (runtime)"},
      {"raw", "raw Fast DDS, the runtime's QoS"},
      {"stock", "raw Fast DDS, stock keep-all"}};
  Row row{.path = labels.at(path), .expected = count};
  std::string out = fmt::format("/tmp/backpressure_bench_{}.txt", getpid());
  pid_t child = fork();
  if (child == 0) {
    execl(self.c_str(), self.c_str(), "--subscriber", path.c_str(), std::to_string(count).c_str(),
          out.c_str(), nullptr);
    _exit(127);
  }
  auto wait_matched = [](auto matched) {
    for (int i = 0; i < 1000 && !matched(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // let discovery settle
  };
  double cpu_before = own_cpu_seconds();
  Steady::time_point start;
  if (path == "runtime") {
    mocap::ComponentHost host({.name = "bench_publisher", .threads = 2, .dds = {}});
    auto& source = static_cast<Source&>(host.add(kSource, {.name = "source"}));
    host.start();
    wait_matched([&] { return source.publisher.matched_subscribers() > 0; });
    cpu_before = own_cpu_seconds();
    start = Steady::now();
    publish_all(count, [&](Array message) { source.publisher.publish(std::move(message)); });
    row.blocked_s = seconds(source.publisher.stats().blocked);
    rusage usage{};
    wait4(child, nullptr, 0, &usage);
    row.subscriber_cpu_s = cpu_seconds(usage);
    row.publisher_cpu_s = own_cpu_seconds() - cpu_before;
  } else {
    RawEndpoint endpoint(path == "stock");
    endpoint.make_writer();
    wait_matched([&] { return endpoint.matched > 0; });
    cpu_before = own_cpu_seconds();
    start = Steady::now();
    row.blocked_s = publish_all(count, [&](Array message) { endpoint.write(message); });
    rusage usage{};
    wait4(child, nullptr, 0, &usage);
    row.subscriber_cpu_s = cpu_seconds(usage);
    row.publisher_cpu_s = own_cpu_seconds() - cpu_before;
  }
  row.run_s = seconds(Steady::now() - start);
  std::ifstream in(out);
  int64_t work_ns = 0;
  in >> row.delivered >> row.in_order >> work_ns;
  row.work_s = double(work_ns) / 1e9;
  std::remove(out.c_str());
  return row;
}

void print(const Row& row) {
  std::string subscriber_cpu =
      row.subscriber_cpu_s < 0 ? "(same)" : fmt::format("{:.2f}", row.subscriber_cpu_s);
  fmt::print(
      "| {:<31} | {:>5} of {:<5} | {:>8} | {:>7.1f} | {:>8.1f} | {:>8.1f} | {:>5.0f} % | {:>8.2f} "
      "| {:>8} |\n",
      row.path, row.delivered, row.expected, row.in_order, row.delivered / row.run_s,
      row.delivered / row.work_s, row.blocked_s, 100 * row.blocked_s / row.run_s,
      row.publisher_cpu_s, subscriber_cpu);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 4 && args[0] == "--subscriber") {
    return run_subscriber(args[1], std::stoi(args[2]), args[3]);
  }
  bool quick = !args.empty() && args[0] == "--quick";
  int count = quick ? 2000 : 5000;
  std::string self = std::filesystem::canonical("/proc/self/exe").string();
  fmt::print(
      "backpressure_bench: {} FiducialArray(12) messages, reliable (keep_all, depth 1000), "
      "published "
      "as fast as publish() returns, into a subscriber that sleeps {} ms per message; {} cores.\n"
      "capacity: what the subscriber's work allows (messages / time in its callbacks). blocked: "
      "time the publisher spent in publish(). CPU: user + system time of each process over "
      "the run.\n\n",
      count, kWork.count(), std::thread::hardware_concurrency());
  fmt::print(
      "| path                            | delivered      | in order | msgs/s  | capacity | "
      "blocked s | share   | pub CPU s | sub CPU s |\n"
      "|---------------------------------|----------------|----------|---------|----------|"
      "-----------|---------|-----------|-----------|\n");
  print(run_in_process(count));
  for (const char* path : {"runtime", "raw", "stock"}) {
    print(run_between_processes(self, path, count));
  }
  return 0;
}
