// The cameras' messages of one capture time, gathered for the fusion: a volume's cameras are
// stamped at capture, and their messages arrive in any order, some late, some never (a camera
// that stopped). A frame is complete when every live camera has given its message for that
// capture time, or when the wait for the late ones has run out (sized to the frame rate, as the
// capture times show it); a camera silent for longer than `silent_after` (or not heard yet) is
// left out of the frames that follow, which then wait for it no more (said by the frame, so
// coverage can be reported), until its next message, which takes it back.
//
//   FrameAssembler<FiducialArray> frames(camera_count, options);
//   frames.add(camera, stamp, message, now);        // as each arrives
//   for (auto& frame : frames.take_ready(now)) fuse(frame);
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace mocap::volume {

struct FrameAssemblerOptions {
  // Messages whose stamps differ by no more than this are one capture time (cameras triggered
  // together still stamp a little apart).
  std::chrono::nanoseconds same_capture{std::chrono::milliseconds(2)};
  // How long a frame waits for its late cameras after its first message arrived, at most.
  std::chrono::nanoseconds wait{std::chrono::milliseconds(30)};
  // The wait as a share of the frame period, when that is shorter than `wait`: a frame still
  // waiting when the next is captured delays every frame behind it. The period is the median
  // interval between the last capture times handed out (robust to a dropped frame). 0: `wait`
  // alone. A whole period, because cameras that capture together and share a host's cores are
  // processed in turn: four cameras on two cores give their messages up to two processing times
  // apart, and more on a busy host. A third of the period (5 ms at most) left 3 % of the
  // frames without a camera in 20 s beside a compiler, and a body missed in one frame can take
  // several to find again. A complete frame still goes out as its last message arrives: only a
  // frame short of a camera waits longer.
  double wait_share_of_frame = 1.0;
  // A camera with no message for this long is left out of the frames that follow.
  std::chrono::nanoseconds silent_after{std::chrono::milliseconds(500)};

  // Why these options cannot be used, naming the field ("silent_after: 0 ms is not above 0");
  // nullopt when they can. FrameAssembler's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

template <class Message>
struct AssembledFrame {
  int64_t stamp_ns = 0;  // the capture time: the earliest stamp of its messages
  // One slot per camera: its message, or nothing (late past the wait, silent, or none).
  std::vector<std::optional<Message>> messages;
  std::vector<bool> silent;  // per camera: left out as silent when the frame was made
  bool complete = false;     // every camera that was not silent gave its message
};

template <class Message>
class FrameAssembler {
 public:
  using Clock = std::chrono::steady_clock;

  FrameAssembler(int cameras, FrameAssemblerOptions options = {})
      : options_(options), last_heard_(static_cast<size_t>(cameras)) {
    if (auto problem = options_.problem()) {
      throw std::invalid_argument("FrameAssemblerOptions::" + *problem);
    }
  }

  // A camera's message for the capture time `stamp_ns`, arriving at `now`. A message for a
  // capture time already handed out is dropped (counted in late_drops()).
  void add(int camera, int64_t stamp_ns, Message message, Clock::time_point now) {
    last_heard_[static_cast<size_t>(camera)] = now;
    if (handed_out_ && stamp_ns <= *handed_out_ + options_.same_capture.count()) {
      ++late_drops_;
      return;
    }
    Pending& pending = pending_for(stamp_ns, now);
    pending.frame.messages[static_cast<size_t>(camera)] = std::move(message);
  }

  // The frames that are complete or whose wait has run out, oldest first; a frame never comes
  // out before an older one.
  std::vector<AssembledFrame<Message>> take_ready(Clock::time_point now) {
    std::vector<AssembledFrame<Message>> ready;
    const std::vector<bool> silent = silent_cameras(now);
    while (!pending_.empty()) {
      auto oldest = pending_.begin();
      Pending& pending = oldest->second;
      bool complete = true;
      for (size_t c = 0; c < silent.size(); ++c) {
        complete = complete && (silent[c] || pending.frame.messages[c].has_value());
      }
      if (!complete && now - pending.first_arrival < wait_) break;
      pending.frame.silent = silent;
      pending.frame.complete = complete;
      if (handed_out_) measure_period(oldest->first - *handed_out_);
      handed_out_ = oldest->first;
      ready.push_back(std::move(pending.frame));
      pending_.erase(oldest);
    }
    return ready;
  }

  int64_t late_drops() const { return late_drops_; }
  // The frame period the capture times show (0 until enough frames came out), and the wait a
  // frame gets now.
  std::chrono::nanoseconds frame_period() const { return frame_period_; }
  std::chrono::nanoseconds wait() const { return wait_; }

 private:
  static constexpr size_t kIntervalsKept = 15;

  void measure_period(int64_t interval_ns) {
    intervals_.push_back(interval_ns);
    if (intervals_.size() > kIntervalsKept) intervals_.pop_front();
    if (intervals_.size() < kIntervalsKept / 2 + 1) return;
    std::vector<int64_t> sorted(intervals_.begin(), intervals_.end());
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    frame_period_ = std::chrono::nanoseconds(sorted[sorted.size() / 2]);
    if (options_.wait_share_of_frame > 0) {
      wait_ = std::min(options_.wait, std::chrono::round<std::chrono::nanoseconds>(
                                          frame_period_ * options_.wait_share_of_frame));
    }
  }

  struct Pending {
    AssembledFrame<Message> frame;
    Clock::time_point first_arrival;
  };

  Pending& pending_for(int64_t stamp_ns, Clock::time_point now) {
    for (auto& [stamp, pending] : pending_) {
      if (std::abs(stamp - stamp_ns) <= options_.same_capture.count()) return pending;
    }
    Pending& pending = pending_[stamp_ns];
    pending.frame.stamp_ns = stamp_ns;
    pending.frame.messages.resize(last_heard_.size());
    pending.first_arrival = now;
    return pending;
  }

  std::vector<bool> silent_cameras(Clock::time_point now) const {
    std::vector<bool> silent(last_heard_.size());
    for (size_t c = 0; c < silent.size(); ++c) {
      silent[c] = !last_heard_[c] || now - *last_heard_[c] > options_.silent_after;
    }
    return silent;
  }

  FrameAssemblerOptions options_;
  std::vector<std::optional<Clock::time_point>> last_heard_;
  std::map<int64_t, Pending> pending_;  // by capture time
  std::optional<int64_t> handed_out_;   // the latest capture time handed out
  std::deque<int64_t> intervals_;       // between the last capture times handed out
  std::chrono::nanoseconds frame_period_{0};
  std::chrono::nanoseconds wait_ = options_.wait;
  int64_t late_drops_ = 0;
};

// Which of the ready frames (their capture times, oldest first) a fusion that is behind fuses:
// the newest `newest`, and enough of the older ones that no two frames fused one after the
// other lie more than `max_gap_ns` apart, counting from `last_fused_ns` (the frame fused
// before them, if any). A tracker bridges a gap that short with its motion model; a backlog
// skipped whole (a tenth of a second on a busy machine) would lose every robot at once and
// leave identical ones to be told apart afresh. Indices, ascending.
std::vector<size_t> frames_to_fuse(const std::vector<int64_t>& stamps_ns,
                                   std::optional<int64_t> last_fused_ns, size_t newest,
                                   int64_t max_gap_ns);

}  // namespace mocap::volume
