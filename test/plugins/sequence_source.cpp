// sequence_source (test plugin): publishes the test stream of sequence_message.hpp.
#include <fstream>

#include <fmt/format.h>

#include <mocap/component.hpp>

#include "sequence_message.hpp"

namespace mocap::test {
namespace {

class SequenceSource final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.description("Test stream: numbered FiducialArrays whose content a sink can check.");
    spec.parameter("count", 1000, "messages to publish; 0 for no end").min(0);
    spec.parameter("batch", 10, "messages per tick").min(1);
    spec.parameter("period_s", 0.01, "seconds between ticks").range(1e-5, 60);
    spec.parameter("subscribers", 1, "matched subscribers to wait for before publishing").min(0);
    spec.parameter("summary_file", std::string(),
                   "where the publisher's figures go (YAML) once `count` are published");
    spec.parameter("stop_when_done", false, "stop the process once `count` are published");
    spec.publishes<mocap_msgs::msg::FiducialArray>(kSequenceTopic, Qos::reliable(),
                                                   "the numbered stream");
  }

  explicit SequenceSource(Context& context) : Component(context) {
    count_ = param<int>("count");
    batch_ = param<int>("batch");
    subscribers_ = param<size_t>("subscribers");
    summary_file_ = param<std::string>("summary_file");
    stop_when_done_ = param<bool>("stop_when_done");
    publisher_ = create_publisher<mocap_msgs::msg::FiducialArray>(kSequenceTopic);
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(param<double>("period_s"))),
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
      log().info(
          "published {} messages in {:.3f} s; {} waited for subscribers, {} ms in all", count_,
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started_at_).count(),
          stats.waited, ms(stats.blocked));
      if (!summary_file_.empty()) {
        std::ofstream(summary_file_) << fmt::format(
            "published: {}\nwaited: {}\nblocked_ms: {}\nlongest_wait_ms: {}\ndropped: {}\n"
            "elapsed_ms: {}\n",
            stats.published, stats.waited, ms(stats.blocked), ms(stats.longest_wait), stats.dropped,
            ms(std::chrono::steady_clock::now() - started_at_));
      }
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
