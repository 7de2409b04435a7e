// Latency and throughput of one hop: in-process through the runtime; between processes through
// the runtime on Fast DDS and through raw Fast DDS with the same type (its fastddsgen type
// support) and the same QoS; through the runtime on Cyclone DDS and through raw Cyclone DDS (its
// C API, with the runtime's type support, which serializes as fastddsgen's does) and the same
// QoS; and across implementations, from the runtime on Fast DDS to the runtime on Cyclone DDS.
// All measured in this run.
//
//   build/bin/transport_bench [--quick]
//
// One-way latency: the publisher stamps each message with CLOCK_MONOTONIC just before
// publishing, the subscriber subtracts it from its own reading on arrival (processes of one
// host share the clock). Throughput: reliable QoS, publishing as fast as flow control allows,
// from the first publication to the last arrival.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
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
#include <sensor_msgs/msg/ImagePubSubTypes.h>
#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "bench/one_hop.hpp"

#include "dds/cyclonedds/cyclonedds_qos.hpp"
#include "dds/cyclonedds/cyclonedds_transport.hpp"
#include "dds/cyclonedds/cyclonedds_type_support.hpp"
#include "dds/dds_transport.hpp"
#include "dds/fastdds/fastdds_qos.hpp"

namespace {

namespace dds = eprosima::fastdds::dds;
using namespace mocap::one_hop;

template <class T>
size_t serialized_bytes(const T& message) {
  return mocap::message_type<T>().serialized_size(&message);
}

// --- the runtime's side -----------------------------------------------------------------

// --- raw Fast DDS -------------------------------------------------------------------------

template <class T>
struct PubSubTypeOf;
template <>
struct PubSubTypeOf<mocap_msgs::msg::FiducialArray> {
  using type = mocap_msgs::msg::FiducialArrayPubSubType;
};
template <>
struct PubSubTypeOf<sensor_msgs::msg::Image> {
  using type = sensor_msgs::msg::ImagePubSubType;
};

// A participant with one topic, as a program using Fast DDS directly would set it up.
template <class T>
class RawEndpoint : public dds::DataReaderListener, public dds::DataWriterListener {
 public:
  RawEndpoint() {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    participant_ = factory->create_participant(mocap::resolve_domain_id(0),
                                               mocap::to_participant_qos({}, "raw"));
    dds::TypeSupport type(new typename PubSubTypeOf<T>::type());
    type.register_type(participant_);
    topic_ = participant_->create_topic(mocap::dds_topic_name(kTopic), type.get_type_name(),
                                        dds::TOPIC_QOS_DEFAULT);
  }
  ~RawEndpoint() override {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }

  dds::DataWriter* make_writer() {
    auto* publisher = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    writer_ =
        publisher->create_datawriter(topic_, mocap::to_writer_qos(mocap::Qos::reliable()), this);
    return writer_;
  }

  void make_reader() {
    auto* subscriber = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    subscriber->create_datareader(topic_, mocap::to_reader_qos(mocap::Qos::reliable()), this);
  }

  void on_data_available(dds::DataReader* reader) override {
    dds::SampleInfo info;
    while (reader->take_next_sample(&sample_, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) received.add(sample_);
    }
  }

  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    matched = status.current_count;
  }

  // A full keep-all history makes a write wait (at most mocap::kWriteWaitSlice, then it
  // times out, and also spuriously in Fast DDS 2.9); the runtime writes again until there is
  // room, and so does this reference, so both deliver everything.
  void write(T& message) {
    while (writer_->write(&message, dds::HANDLE_NIL) == ReturnCode_t::RETCODE_TIMEOUT) {
    }
  }

  std::atomic<int> matched{0};

 private:
  dds::DomainParticipant* participant_ = nullptr;
  dds::Topic* topic_ = nullptr;
  dds::DataWriter* writer_ = nullptr;
  T sample_;
};

// --- raw Cyclone DDS ----------------------------------------------------------------------

// A participant with one topic, through Cyclone's C API with the runtime's QoS.
template <class T>
class RawCycloneEndpoint {
 public:
  RawCycloneEndpoint() {
    participant_ = dds_create_participant(mocap::resolve_domain_id(0), nullptr, nullptr);
    ddsi_sertype* type = mocap::make_cyclonedds_sertype(mocap::message_type<T>());
    topic_ = dds_create_topic_sertype(participant_, mocap::dds_topic_name(kTopic).c_str(), &type,
                                      nullptr, nullptr, nullptr);
  }
  ~RawCycloneEndpoint() { dds_delete(participant_); }

  void make_writer() {
    dds_qos_t* qos = dds_create_qos();
    mocap::to_cyclone_writer_qos(mocap::Qos::reliable(), qos);
    dds_listener_t* listener = dds_create_listener(this);
    dds_lset_publication_matched(
        listener, [](dds_entity_t, const dds_publication_matched_status_t status, void* self) {
          static_cast<RawCycloneEndpoint*>(self)->matched = int(status.current_count);
        });
    writer_ = dds_create_writer(participant_, topic_, qos, listener);
    dds_delete_listener(listener);
    dds_delete_qos(qos);
  }

  void make_reader() {
    dds_qos_t* qos = dds_create_qos();
    mocap::to_cyclone_reader_qos(mocap::Qos::reliable(), qos);
    dds_listener_t* listener = dds_create_listener(this);
    dds_lset_data_available(listener, [](dds_entity_t reader, void* self) {
      static_cast<RawCycloneEndpoint*>(self)->take(reader);
    });
    dds_create_reader(participant_, topic_, qos, listener);
    dds_delete_listener(listener);
    dds_delete_qos(qos);
  }

  // As with raw Fast DDS: write again while the history is full.
  void write(T& message) {
    while (dds_write(writer_, &message) == DDS_RETCODE_TIMEOUT) {
    }
  }

  std::atomic<int> matched{0};

 private:
  void take(dds_entity_t reader) {
    ddsi_serdata* serdata = nullptr;
    dds_sample_info_t info;
    while (dds_takecdr(reader, &serdata, 1, &info, DDS_ANY_STATE) > 0) {
      if (info.valid_data) {
        mocap::message_type<T>().deserialize(mocap::serialized_bytes(serdata), &sample_);
        received.add(sample_);
      }
      mocap::release(serdata);
    }
  }

  dds_entity_t participant_ = 0;
  dds_entity_t topic_ = 0;
  dds_entity_t writer_ = 0;
  T sample_;
};

// The middleware of the runtime on each side of a path.
std::string publisher_implementation(const std::string& path) {
  return path == "runtime-cyclonedds" ? "cyclonedds" : "fastdds";
}
std::string subscriber_implementation(const std::string& path) {
  return path == "runtime-cyclonedds" || path == "cross" ? "cyclonedds" : "fastdds";
}

// --- the subscriber process -------------------------------------------------------------

// Tells the publisher, through a file beside `out`, when the first priming message arrived,
// then waits for `total` counted ones.
void receive_all(int total, const std::string& out) {
  if (received.wait_primed(std::chrono::seconds(60))) std::ofstream(out + ".ready");
  received.wait_for(total, std::chrono::seconds(120));
}

template <class T>
int run_subscriber(const std::string& path, int total, const std::string& out) {
  auto report = [&] {
    std::lock_guard lock(received.mutex);
    std::ofstream file(out);
    file << received.count << " " << received.first_ns << " " << received.last_ns << "\n";
    for (double l : received.latencies_us) file << l << "\n";
  };
  if (path == "raw") {
    RawEndpoint<T> endpoint;
    endpoint.make_reader();
    receive_all(total, out);
    report();
    return 0;
  }
  if (path == "raw-cyclonedds") {
    RawCycloneEndpoint<T> endpoint;
    endpoint.make_reader();
    receive_all(total, out);
    report();
    return 0;
  }
  mocap::ComponentHost host({.name = "bench_subscriber",
                             .threads = 2,
                             .dds = {.implementation = subscriber_implementation(path)}});
  host.add(kSubscriberFactory<T>, {.name = "subscriber"});
  host.start();
  receive_all(total, out);
  host.stop();
  report();
  return 0;
}

// --- the publisher's side ---------------------------------------------------------------

struct Result {
  std::vector<double> latencies_us;  // pooled over rounds
  std::vector<double> msgs_per_s;    // one per round
  double bytes = 0;
  int delivered = 0, expected = 0;  // summed over rounds

  void merge(const Result& round) {
    latencies_us.insert(latencies_us.end(), round.latencies_us.begin(), round.latencies_us.end());
    msgs_per_s.insert(msgs_per_s.end(), round.msgs_per_s.begin(), round.msgs_per_s.end());
    bytes = round.bytes;
    delivered += round.delivered;
    expected += round.expected;
  }
};

Result make_result(int delivered, int count, int64_t first_publish_ns, int64_t last_ns,
                   std::vector<double> latencies, size_t bytes, bool throughput) {
  Result r;
  r.delivered = delivered;
  r.expected = kWarmup + count;
  r.bytes = double(bytes);
  if (throughput) {
    if (last_ns > first_publish_ns) {
      r.msgs_per_s.push_back(delivered / (double(last_ns - first_publish_ns) / 1e9));
    }
  } else {
    r.latencies_us = std::move(latencies);
  }
  return r;
}

Result result_from(const std::string& file, int count, int64_t first_publish_ns, size_t bytes,
                   bool throughput) {
  std::ifstream in(file);
  int delivered = 0;
  int64_t first_ns = 0, last_ns = 0;
  in >> delivered >> first_ns >> last_ns;
  std::vector<double> latencies;
  for (double l; in >> l;) latencies.push_back(l);
  return make_result(delivered, count, first_publish_ns, last_ns, std::move(latencies), bytes,
                     throughput);
}

Result from_received(int count, int64_t first_publish_ns, size_t bytes, bool throughput) {
  std::lock_guard lock(received.mutex);
  return make_result(received.count, count, first_publish_ns, received.last_ns,
                     received.latencies_us, bytes, throughput);
}

void reset_received() {
  std::lock_guard lock(received.mutex);
  received.latencies_us.clear();
  received.count = 0;
  received.first_ns = received.last_ns = 0;
}

template <class T>
Result run_intra(const Size& size, bool throughput) {
  reset_received();
  int count = throughput ? size.throughput_count : size.latency_count;
  mocap::ComponentHost host({.name = "bench", .threads = 2, .dds = {.enabled = false}});
  auto& publisher =
      static_cast<BenchPublisher<T>&>(host.add(kPublisherFactory<T>, {.name = "pub"}));
  host.add(kSubscriberFactory<T>, {.name = "sub"});
  host.start();
  T message = prototype<T>(size);
  // In-process subscribers receive the object itself, so each message needs one of its own:
  // taken from a few made beforehand (as a camera driver fills frame buffers) when no
  // subscriber holds it any more, so that making it is not part of the hop.
  std::vector<std::shared_ptr<T>> pool;
  for (int i = 0; i < 8; ++i) pool.push_back(std::make_shared<T>(message));
  size_t next = 0;
  int64_t first = publish_all(count, throughput ? 0 : size.latency_rate_hz, [&] {
    std::shared_ptr<T>& slot = pool[next++ % pool.size()];
    if (slot.use_count() > 1) slot = std::make_shared<T>(message);
    stamp(*slot);
    publisher.publisher.publish(slot);
    return stamp_ns(*slot);
  });
  received.wait_for(kWarmup + count, std::chrono::seconds(60));
  host.stop();
  return from_received(count, first, serialized_bytes(message), throughput);
}

template <class T>
Result run_between_processes(const std::string& self, const std::string& path, const Size& size,
                             bool throughput) {
  int count = throughput ? size.throughput_count : size.latency_count;
  std::string out = fmt::format("/tmp/transport_bench_{}.txt", getpid());
  pid_t child = fork();
  if (child == 0) {
    execl(self.c_str(), self.c_str(), "--subscriber", path.c_str(),
          size.image ? "image" : "fiducials", std::to_string(kWarmup + count).c_str(), out.c_str(),
          nullptr);
    _exit(127);
  }
  T message = prototype<T>(size);
  int64_t first = 0;
  int rate = throughput ? 0 : size.latency_rate_hz;
  // Once the publisher sees its subscriber, priming messages until the subscriber got one.
  std::string ready = out + ".ready";
  auto wait_matched = [&](auto matched, auto write) {
    for (int i = 0; i < 1000 && !matched(); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    T priming = message;
    priming.header().frame_id(kPrimingFrame);
    for (int i = 0; i < 1000 && !std::filesystem::exists(ready); ++i) {
      write(priming);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  };
  if (path == "raw") {
    RawEndpoint<T> endpoint;
    endpoint.make_writer();
    wait_matched([&] { return endpoint.matched > 0; }, [&](T& m) { endpoint.write(m); });
    first = publish_all(count, rate, [&] {
      stamp(message);
      endpoint.write(message);
      return stamp_ns(message);
    });
    waitpid(child, nullptr, 0);
  } else if (path == "raw-cyclonedds") {
    RawCycloneEndpoint<T> endpoint;
    endpoint.make_writer();
    wait_matched([&] { return endpoint.matched > 0; }, [&](T& m) { endpoint.write(m); });
    first = publish_all(count, rate, [&] {
      stamp(message);
      endpoint.write(message);
      return stamp_ns(message);
    });
    waitpid(child, nullptr, 0);
  } else {
    mocap::ComponentHost host({.name = "bench_publisher",
                               .threads = 2,
                               .dds = {.implementation = publisher_implementation(path)}});
    auto& publisher =
        static_cast<BenchPublisher<T>&>(host.add(kPublisherFactory<T>, {.name = "pub"}));
    host.start();
    wait_matched([&] { return publisher.publisher.matched_subscribers() > 0; },
                 [&](T& m) { publisher.publisher.publish(std::make_shared<T>(m)); });
    // Serialized during publish(): one object can be reused, as the raw reference does.
    auto shared = std::make_shared<T>(message);
    first = publish_all(count, rate, [&] {
      stamp(*shared);
      publisher.publisher.publish(shared);
      return stamp_ns(*shared);
    });
    waitpid(child, nullptr, 0);
  }
  Result r = result_from(out, count, first, serialized_bytes(message), throughput);
  std::remove(out.c_str());
  std::remove(ready.c_str());
  return r;
}

// The floor under any hand-off between threads on this machine: a condition variable
// waking a waiting thread, at the same message rate (the idle time before each wake-up
// matters on virtual machines).
Result measure_thread_wakeup(int rate_hz, int count) {
  std::mutex mutex;
  std::condition_variable cv;
  int64_t sent = 0;
  bool done = false;
  Result r;
  std::thread waiter([&] {
    std::unique_lock lock(mutex);
    for (int i = 0; i < kWarmup + count; ++i) {
      cv.wait(lock, [&] { return sent != 0 || done; });
      if (done) return;
      if (i >= kWarmup) r.latencies_us.push_back(double(steady_ns() - sent) / 1e3);
      sent = 0;
    }
  });
  publish_all(count, rate_hz, [&] {
    int64_t now;
    {
      std::lock_guard lock(mutex);
      sent = now = steady_ns();
    }
    cv.notify_one();
    return now;
  });
  {
    std::lock_guard lock(mutex);
    done = true;
  }
  cv.notify_one();
  waiter.join();
  r.delivered = r.expected = kWarmup + count;
  return r;
}

double median(std::vector<double> values) { return quantile(std::move(values), 0.5); }

void print_row(const std::string& size, const std::string& path, const Result& latency,
               const Result* throughput) {
  std::string notes;
  int delivered = latency.delivered + (throughput ? throughput->delivered : 0);
  int expected = latency.expected + (throughput ? throughput->expected : 0);
  if (delivered != expected) notes = fmt::format("  (delivered {} of {})", delivered, expected);
  std::string msgs = "", mb = "";
  if (throughput) {
    double rate = median(throughput->msgs_per_s);
    msgs = fmt::format("{:.0f}", rate);
    mb = fmt::format("{:.1f}", rate * throughput->bytes / 1e6);
  }
  fmt::print("| {:<28} | {:<33} | {:>9.1f} | {:>9.1f} | {:>10} | {:>8} |{}\n", size, path,
             quantile(latency.latencies_us, 0.5), quantile(latency.latencies_us, 0.99), msgs, mb,
             notes);
}

// The ratio of `a` to `b`: median and p99 latency, median throughput.
void print_ratio(const std::string& label, const Result& a_latency, const Result& b_latency,
                 const Result& a_throughput, const Result& b_throughput) {
  fmt::print("| {:<28} | {:<33} | {:>9.2f} | {:>9.2f} | {:>10.2f} | {:>8} |\n", "", label,
             quantile(a_latency.latencies_us, 0.5) / quantile(b_latency.latencies_us, 0.5),
             quantile(a_latency.latencies_us, 0.99) / quantile(b_latency.latencies_us, 0.99),
             median(a_throughput.msgs_per_s) / median(b_throughput.msgs_per_s), "");
}

template <class T>
void measure(const std::string& self, const Size& size, int rounds) {
  // Between processes: the runtime and the raw reference on each implementation, and the
  // runtime from one implementation to the other.
  const std::vector<std::string> paths = {"runtime", "raw", "runtime-cyclonedds", "raw-cyclonedds",
                                          "cross"};
  Result floor, intra_latency, intra_throughput;
  std::map<std::string, Result> latency, throughput;
  Size part = size;
  part.latency_count = std::max(1, size.latency_count / rounds);
  for (int round = 0; round < rounds; ++round) {
    floor.merge(measure_thread_wakeup(size.latency_rate_hz, part.latency_count));
    intra_latency.merge(run_intra<T>(part, false));
    intra_throughput.merge(run_intra<T>(part, true));
    // Rotate the order, so that drift in the machine's load favours no path.
    for (size_t turn = 0; turn < paths.size(); ++turn) {
      const std::string& path = paths[(turn + round) % paths.size()];
      latency[path].merge(run_between_processes<T>(self, path, part, false));
      throughput[path].merge(run_between_processes<T>(self, path, part, true));
    }
  }
  std::string label = fmt::format("{} @{} Hz", size.label, size.latency_rate_hz);
  print_row(label, "thread wake-up (floor)", floor, nullptr);
  print_row("", "intra-process (runtime)", intra_latency, &intra_throughput);
  print_row("", "inter-process (runtime, Fast DDS)", latency["runtime"], &throughput["runtime"]);
  print_row("", "inter-process (raw Fast DDS)", latency["raw"], &throughput["raw"]);
  print_row("", "inter-process (runtime, Cyclone)", latency["runtime-cyclonedds"],
            &throughput["runtime-cyclonedds"]);
  print_row("", "inter-process (raw Cyclone DDS)", latency["raw-cyclonedds"],
            &throughput["raw-cyclonedds"]);
  print_row("", "Fast DDS -> Cyclone (runtime)", latency["cross"], &throughput["cross"]);
  print_ratio("runtime / raw, Fast DDS", latency["runtime"], latency["raw"], throughput["runtime"],
              throughput["raw"]);
  print_ratio("runtime / raw, Cyclone DDS", latency["runtime-cyclonedds"],
              latency["raw-cyclonedds"], throughput["runtime-cyclonedds"],
              throughput["raw-cyclonedds"]);
  // Against the slower of the two implementations' runtime hops (by median latency).
  const std::string& slower = quantile(latency["runtime"].latencies_us, 0.5) >
                                      quantile(latency["runtime-cyclonedds"].latencies_us, 0.5)
                                  ? std::string("runtime")
                                  : std::string("runtime-cyclonedds");
  print_ratio("cross / slower implementation", latency["cross"], latency[slower],
              throughput["cross"], throughput[slower]);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 5 && args[0] == "--subscriber") {
    int total = std::stoi(args[3]);
    if (args[2] == "image") return run_subscriber<sensor_msgs::msg::Image>(args[1], total, args[4]);
    return run_subscriber<mocap_msgs::msg::FiducialArray>(args[1], total, args[4]);
  }
  bool quick = !args.empty() && args[0] == "--quick";
  if (getenv("MOCAP_DOMAIN_ID") == nullptr) {
    setenv("MOCAP_DOMAIN_ID", std::to_string(200 + getpid() % 30).c_str(), 1);
  }
  int rounds = quick ? 2 : 6;
  int scale = quick ? 4 : 1;
  std::vector<Size> sizes = {
      {"FiducialArray (12)", false, 12, 0, 1000, 6000 / scale, 20000 / scale},
      {"Image 64 KiB", true, 256, 256, 500, 3000 / scale, 3000 / scale},
      {"Image 1280x720 mono8", true, 1280, 720, 100, 1200 / scale, 500 / scale},
  };
  std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  fmt::print(
      "transport_bench: one hop, reliable QoS, {} cores, {} rounds with the paths "
      "interleaved.\nLatency: one-way, at the rate shown, pooled over rounds. Throughput: "
      "publishing as fast as flow control allows, median of rounds.\n\n",
      std::thread::hardware_concurrency(), rounds);
  fmt::print("| {:<28} | {:<33} | {:>9} | {:>9} | {:>10} | {:>8} |\n", "message", "path",
             "median us", "p99 us", "msgs/s", "MB/s");
  fmt::print("|{:-<30}|{:-<35}|{:-<11}|{:-<11}|{:-<12}|{:-<10}|\n", "", "", "", "", "", "");
  measure<mocap_msgs::msg::FiducialArray>(self, sizes[0], rounds);
  measure<sensor_msgs::msg::Image>(self, sizes[1], rounds);
  measure<sensor_msgs::msg::Image>(self, sizes[2], rounds);
  fmt::print(
      "\ntargets: intra-process hop <= 10 us median; runtime inter-process hop <= 1.10 x the "
      "raw figure of its implementation; the hop from one implementation to the other <= 1.25 "
      "x the slower implementation's (ratios above 1: slower latency, or, for msgs/s, below 1: "
      "less throughput)\n");
  return 0;
}
