// sequence_sink (test plugin): checks the test stream and writes what it saw to a file.
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include <mocap/component.hpp>

#include "test/plugins/sequence_message.hpp"

namespace mocap::test {
namespace {

struct Settings {
  int expect = 1000;
  std::string summary_file;
  double timeout_s = 60.0;
  int log_every = 0;
  int finish_at = -1;
  bool stop_when_done = true;
  double work_s = 0.0;
  int stall_every = 0;
  double stall_s = 1.0;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("expect",
             "messages after which the summary is written and the process "
             "stops; 0 for never",
             &Settings::expect)
        .min(0)
        .add("summary_file", "where the summary goes (YAML)", &Settings::summary_file)
        .add("timeout_s", "give up after this long: summary, then exit code 3",
             &Settings::timeout_s)
        .min(0.1)
        .add("log_every", "log 'received N' every N messages; 0 for never", &Settings::log_every)
        .min(0)
        .add("finish_at",
             "finish when this sequence number arrives, however many came before it; -1 "
             "for never",
             &Settings::finish_at)
        .min(-1)
        .add("stop_when_done", "stop the process once the summary is written",
             &Settings::stop_when_done)
        .add("work_s", "seconds each message keeps the sink busy (a slow subscriber)",
             &Settings::work_s)
        .range(0.0, 1.0)
        .add("stall_every", "every this many messages, the sink stalls; 0 for never",
             &Settings::stall_every)
        .min(0)
        .add("stall_s", "seconds each stall lasts", &Settings::stall_s)
        .range(0.0, 60.0);

class SequenceSink final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description("Test sink: checks the numbered stream, writes a summary, then stops.");
    kParameters.declare(spec);
    spec.subscribes<mocap_msgs::msg::FiducialArray>(kSequenceTopic, Qos::reliable(),
                                                    "the numbered stream");
  }

  explicit SequenceSink(Context& context) : Component(context) {
    expect_ = settings_.expect;
    log_every_ = settings_.log_every;
    summary_file_ = settings_.summary_file;
    stop_when_done_ = settings_.stop_when_done;
    finish_at_ = settings_.finish_at;
    work_ = std::chrono::duration<double>(settings_.work_s);
    stall_every_ = settings_.stall_every;
    stall_ = std::chrono::duration<double>(settings_.stall_s);
    create_subscription<mocap_msgs::msg::FiducialArray>(
        kSequenceTopic,
        [this](const std::shared_ptr<const mocap_msgs::msg::FiducialArray>& m) { receive(m); });
    create_timer(std::chrono::duration_cast<std::chrono::nanoseconds>(
                     std::chrono::duration<double>(settings_.timeout_s)),
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
