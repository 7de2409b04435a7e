// sequence_sink (test plugin): checks the test stream and writes what it saw to a file.
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include <mocap/component.hpp>

#include "sequence_message.hpp"

namespace mocap::test {
namespace {

class SequenceSink final : public Component {
 public:
  static void declare(ComponentSpec& spec) {
    spec.description("Test sink: checks the numbered stream, writes a summary, then stops.");
    spec.parameter("expect", 1000,
                   "messages after which the summary is written and the process "
                   "stops; 0 for never")
        .min(0);
    spec.parameter("summary_file", std::string(), "where the summary goes (YAML)");
    spec.parameter("timeout_s", 60.0, "give up after this long: summary, then exit code 3")
        .min(0.1);
    spec.parameter("log_every", 0, "log 'received N' every N messages; 0 for never").min(0);
    spec.parameter("finish_at", -1,
                   "finish when this sequence number arrives, however many came before it; -1 "
                   "for never")
        .min(-1);
    spec.parameter("stop_when_done", true, "stop the process once the summary is written");
    spec.parameter("work_s", 0.0, "seconds each message keeps the sink busy (a slow subscriber)")
        .range(0.0, 1.0);
    spec.parameter("stall_every", 0, "every this many messages, the sink stalls; 0 for never")
        .min(0);
    spec.parameter("stall_s", 1.0, "seconds each stall lasts").range(0.0, 60.0);
    spec.subscribes<mocap_msgs::msg::FiducialArray>(kSequenceTopic, Qos::reliable(),
                                                    "the numbered stream");
  }

  explicit SequenceSink(Context& context) : Component(context) {
    expect_ = param<int64_t>("expect");
    log_every_ = param<int64_t>("log_every");
    summary_file_ = param<std::string>("summary_file");
    stop_when_done_ = param<bool>("stop_when_done");
    finish_at_ = param<int64_t>("finish_at");
    work_ = std::chrono::duration<double>(param<double>("work_s"));
    stall_every_ = param<int64_t>("stall_every");
    stall_ = std::chrono::duration<double>(param<double>("stall_s"));
    create_subscription<mocap_msgs::msg::FiducialArray>(
        kSequenceTopic,
        [this](const std::shared_ptr<const mocap_msgs::msg::FiducialArray>& m) { receive(m); });
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(param<double>("timeout_s"))),
                 [this] { finish(3); });
  }

  // Stopped before it was done (a signal): the summary says what had arrived.
  ~SequenceSink() override { write_summary(); }

 private:
  void receive(const std::shared_ptr<const mocap_msgs::msg::FiducialArray>& message) {
    if (work_.count() > 0) std::this_thread::sleep_for(work_);
    if (stall_every_ > 0 && (received_ + 1) % stall_every_ == 0)
      std::this_thread::sleep_for(stall_);
    int64_t sequence = message->header().stamp().sec();
    if (received_ == 0) first_ = sequence;
    if (sequence <= last_) {
      ++out_of_order_;
    } else if (received_ > 0 && sequence != last_ + 1) {
      missing_ += sequence - last_ - 1;
    }
    last_ = std::max(last_, sequence);
    if (!is_intact(*message)) ++corrupt_;
    if (message->header().frame_id() == object_identity(message.get())) ++same_object_;
    ++received_;
    if (log_every_ > 0 && received_ % log_every_ == 0) log().info("received {}", received_);
    if ((expect_ > 0 && received_ == expect_) || (finish_at_ >= 0 && sequence == finish_at_)) {
      finish(0);
    }
  }

  void write_summary() {
    if (summary_file_.empty() || finished_) return;
    std::ofstream out(summary_file_);
    out << fmt::format(
        "received: {}\nfirst: {}\nlast: {}\nmissing: {}\nout_of_order: {}\ncorrupt: {}\n"
        "same_object: {}\n",
        received_, first_, last_, missing_, out_of_order_, corrupt_, same_object_);
  }

  void finish(int exit_code) {
    if (finished_) return;
    write_summary();
    finished_ = true;
    log().info(
        "received {} messages (first {}, last {}, {} missing, {} out of order, {} corrupt, "
        "{} by pointer)",
        received_, first_, last_, missing_, out_of_order_, corrupt_, same_object_);
    if (stop_when_done_ || exit_code != 0) request_shutdown(exit_code);
  }

  int64_t expect_;
  int64_t log_every_;
  std::string summary_file_;
  bool stop_when_done_;
  int64_t finish_at_;
  std::chrono::duration<double> work_;
  int64_t stall_every_;
  std::chrono::duration<double> stall_;
  int64_t received_ = 0, first_ = -1, last_ = -1, missing_ = 0, out_of_order_ = 0, corrupt_ = 0,
          same_object_ = 0;
  bool finished_ = false;
};

}  // namespace
}  // namespace mocap::test

MOCAP_REGISTER_COMPONENT(mocap::test::SequenceSink, "sequence_sink")
