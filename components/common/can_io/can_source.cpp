#include "common/can_io/can_source.hpp"

#include <algorithm>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "common/can_io/candump_log.hpp"
#include "common/can_io/slcan.hpp"
#include "common/can_io/socketcan.hpp"
#include "common/serial_io/serial_port.hpp"

namespace mocap::can {
namespace {

int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// "a, b, c": the values a setting may take, for its message.
std::string listed(const std::vector<int>& values) {
  std::string list;
  for (int value : values) list += (list.empty() ? "" : ", ") + std::to_string(value);
  return list;
}

class SlcanSource final : public CanSource {
 public:
  explicit SlcanSource(const SlcanSourceOptions& options) : options_(options) {
    std::vector<std::string> commands = slcan_open_commands(options.bitrate);  // may throw
    try {
      port_.emplace(options.device, serial::SerialPortOptions{.baud_rate = options.baud});
      for (const std::string& command : commands) port_->write_all(command);
    } catch (const serial::SerialError& e) {
      throw CanSourceError(e.what());
    }
  }

  ~SlcanSource() override {
    // Leave the adaptor closed, as a set-up script's `slcand` would; it may be gone already.
    try {
      if (port_) port_->write_all(slcan_close_command());
    } catch (const serial::SerialError&) {
    }
  }

  std::vector<CanFrame> read(std::chrono::milliseconds timeout) override {
    char buffer[4096];
    try {
      size_t n = port_->read(buffer, sizeof buffer, timeout);
      if (n > 0) parser_.feed(std::string_view(buffer, n), now_ns());
    } catch (const serial::SerialError& e) {
      throw CanSourceError(e.what());
    }
    return parser_.take_frames();
  }

  std::string description() const override {
    return fmt::format("slcan {} at {} bit/s", options_.device, options_.bitrate);
  }
  uint64_t read_errors() const override { return parser_.stats().errors + parser_.stats().bells; }

 private:
  SlcanSourceOptions options_;
  std::optional<serial::SerialPort> port_;
  SlcanParser parser_;
};

class SocketCanSource final : public CanSource {
 public:
  explicit SocketCanSource(const std::string& interface) try : socket_(interface) {
  } catch (const SocketCanError& e) {
    throw CanSourceError(e.what());
  }

  std::vector<CanFrame> read(std::chrono::milliseconds timeout) override {
    std::vector<CanFrame> frames;
    try {
      // The first frame within the timeout, then whatever else is already queued.
      for (auto frame = socket_.read(timeout); frame; frame = socket_.read({})) {
        frames.push_back(*frame);
        if (frames.size() >= 256) break;
      }
    } catch (const SocketCanError& e) {
      throw CanSourceError(e.what());
    }
    return frames;
  }

  std::string description() const override { return "socketcan " + socket_.interface(); }

 private:
  SocketCan socket_;
};

class CandumpSource final : public CanSource {
 public:
  explicit CandumpSource(const CandumpSourceOptions& options)
      : options_(options), records_(read_candump_file(options.file)) {}

  std::vector<CanFrame> read(std::chrono::milliseconds timeout) override {
    std::vector<CanFrame> frames;
    if (finished()) {
      std::this_thread::sleep_for(timeout);
      return frames;
    }
    if (!options_.recorded_timing) {
      // As fast as possible, in batches that keep the consumer's queues short.
      for (; next_ < records_.size() && frames.size() < 256; ++next_) {
        frames.push_back(recorded_frame(next_));
      }
      return frames;
    }
    auto start = std::chrono::steady_clock::now();
    if (next_ == 0) replay_start_ = start;
    const int64_t first = records_.front().stamp_ns;
    auto due = [&](size_t i) {
      return replay_start_ + std::chrono::nanoseconds(records_[i].stamp_ns - first);
    };
    // Wait for the next frame's time, at most `timeout`, then hand out all that are due.
    std::this_thread::sleep_until(std::min(due(next_), start + timeout));
    auto now = std::chrono::steady_clock::now();
    for (; next_ < records_.size() && due(next_) <= now; ++next_) {
      frames.push_back(recorded_frame(next_));
    }
    return frames;
  }

  bool finished() const override { return next_ >= records_.size(); }
  std::string description() const override {
    return fmt::format("candump {} ({} frames, {})", options_.file, records_.size(),
                       options_.recorded_timing ? "recorded timing" : "as fast as possible");
  }

 private:
  CanFrame recorded_frame(size_t index) const {
    CanFrame frame = records_[index].frame;
    frame.stamp_ns = records_[index].stamp_ns;
    return frame;
  }

  CandumpSourceOptions options_;
  std::vector<CandumpRecord> records_;
  size_t next_ = 0;
  std::chrono::steady_clock::time_point replay_start_;
};

}  // namespace

std::optional<std::string> SlcanSourceOptions::problem() const {
  if (device.empty()) return "device: empty; the adaptor's serial device, e.g. /dev/ttyACM0";
  const std::vector<int> bitrates = slcan_bitrates();
  if (std::find(bitrates.begin(), bitrates.end(), bitrate) == bitrates.end()) {
    return fmt::format("bitrate: {} bit/s is not an SLCAN bitrate; supported: {}", bitrate,
                       listed(bitrates));
  }
  const std::vector<int> bauds = serial::supported_baud_rates();
  if (std::find(bauds.begin(), bauds.end(), baud) == bauds.end()) {
    return fmt::format("baud: {} is not supported; supported: {}", baud, listed(bauds));
  }
  return std::nullopt;
}

std::unique_ptr<CanSource> open_slcan(const SlcanSourceOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("SlcanSourceOptions::" + *problem);
  }
  return std::make_unique<SlcanSource>(options);
}

std::unique_ptr<CanSource> open_socketcan(const std::string& interface) {
  return std::make_unique<SocketCanSource>(interface);
}

std::optional<std::string> CandumpSourceOptions::problem() const {
  if (file.empty()) return "file: empty; a `candump -L` log to read";
  return std::nullopt;
}

std::unique_ptr<CanSource> open_candump(const CandumpSourceOptions& options) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("CandumpSourceOptions::" + *problem);
  }
  return std::make_unique<CandumpSource>(options);
}

}  // namespace mocap::can
