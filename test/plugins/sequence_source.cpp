// sequence_source (test plugin): publishes the test stream of sequence_message.hpp.
#include <fstream>

#include <fmt/format.h>

#include <mocap/component.hpp>

#include "test/plugins/sequence_message.hpp"

namespace mocap::test {
namespace {

struct Settings {
  int count = 1000;
  int batch = 10;
  double period_s = 0.01;
  int subscribers = 1;
  std::string summary_file;
  bool stop_when_done = false;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("count", "messages to publish; 0 for no end", &Settings::count)
        .min(0)
        .add("batch", "messages per tick", &Settings::batch)
        .min(1)
        .add("period_s", "seconds between ticks", &Settings::period_s)
        .range(1e-5, 60)
        .add("subscribers", "matched subscribers to wait for before publishing",
             &Settings::subscribers)
        .min(0)
        .add("summary_file", "where the publisher's figures go (YAML) once `count` are published",
             &Settings::summary_file)
        .add("stop_when_done", "stop the process once `count` are published",
             &Settings::stop_when_done);

class SequenceSource final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description("Test stream: numbered FiducialArrays whose content a sink can check.");
    kParameters.declare(spec);
    spec.publishes<mocap_msgs::msg::FiducialArray>(kSequenceTopic, Qos::reliable(),
                                                   "the numbered stream");
  }

  explicit SequenceSource(Context& context) : Component(context) {
    count_ = settings_.count;
    batch_ = settings_.batch;
    subscribers_ = settings_.subscribers;
    summary_file_ = settings_.summary_file;
    stop_when_done_ = settings_.stop_when_done;
    publisher_ = create_publisher<mocap_msgs::msg::FiducialArray>(kSequenceTopic);
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(settings_.period_s)),
                 [this] { tick(); });
  }

 private:
  void tick() {
    if (!started_) {
      if (publisher_.matched_subscribers() < subscribers_) return;
      started_ = true;
      started_at_ = std::chrono::steady_clock::now();
      log().info("{} subscriber(s) matched; publishing", publisher_.matched_subscribers());
    }
    for (int i = 0; i < batch_ && (count_ == 0 || next_ < count_); ++i) {
      auto message =
          std::make_shared<mocap_msgs::msg::FiducialArray>(make_sequence_message(next_++));
      // In-process subscribers receive this very object; they check its identity.
      message->header().frame_id(object_identity(message.get()));
      publisher_.publish(std::move(message));
    }
    if (count_ != 0 && next_ == count_ && !reported_) {
      reported_ = true;
      PublisherStats stats = publisher_.stats();
      auto ms = [](std::chrono::nanoseconds d) { return d.count() / 1000000; };
      if (!summary_file_.empty()) {
        std::ofstream(summary_file_) << fmt::format(
            "published: {}\nwaited: {}\nblocked_ms: {}\nlongest_wait_ms: {}\ndropped: {}\n"
            "elapsed_ms: {}\n",
            stats.published, stats.waited, ms(stats.blocked), ms(stats.longest_wait), stats.dropped,
            ms(std::chrono::steady_clock::now() - started_at_));
      }
      // Logged after the summary is on disk: tests read it once they see this line.
      log().info(
          "published {} messages in {:.3f} s; {} waited for subscribers, {} ms in all", count_,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started_at_).count(),
          stats.waited, ms(stats.blocked));
      if (stop_when_done_) request_shutdown();
    }
  }

  int count_;
  int batch_;
  size_t subscribers_;
  std::string summary_file_;
  bool stop_when_done_;
  std::chrono::steady_clock::time_point started_at_;
  int next_ = 0;
  bool started_ = false;
  bool reported_ = false;
  Publisher<mocap_msgs::msg::FiducialArray> publisher_;
};

}  // namespace
}  // namespace mocap::test

MOCAP_REGISTER_COMPONENT(mocap::test::SequenceSource, "sequence_source")
