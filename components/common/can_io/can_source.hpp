// Where the PixArt bridge's CAN frames come from, behind one interface: a USB adaptor speaking
// SLCAN on a serial device, a Linux SocketCAN interface, or a `candump -L` log.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/can_io/can_frame.hpp"

namespace mocap::can {

// The device went away or failed (unplugged adaptor, interface down); reopening may help.
class CanSourceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CanSource {
 public:
  virtual ~CanSource() = default;
  // The frames that arrive within `timeout` (none on a quiet bus), stamped with the time they
  // were read, or received if an SLCAN adaptor stamps them (AdaptorClock); a log's frames keep
  // their recorded stamps, as rosbag2 replays keep theirs, so a replay at any pace localizes as the
  // live run did and pairs with what was recorded beside it (the simulator's ground truth). Throws
  // CanSourceError when the device is gone.
  virtual std::vector<CanFrame> read(std::chrono::milliseconds timeout) = 0;
  // A log that has been replayed to its end; live sources never finish.
  virtual bool finished() const { return false; }
  // "slcan /dev/ttyACM0 at 1000000 bit/s", for logs.
  virtual std::string description() const = 0;
  // Frames the source itself could not read (malformed SLCAN messages, adaptor errors).
  virtual uint64_t read_errors() const { return 0; }
};

struct SlcanSourceOptions {
  std::string device;     // serial device of the adaptor, e.g. /dev/ttyACM0
  int bitrate = 1000000;  // of the CAN bus
  int baud = 115200;      // of the serial line (USB adaptors ignore it)

  // Why these options cannot be used, naming the field ("bitrate: 300000 bit/s is not an
  // SLCAN bitrate; ..."); nullopt when they can. open_slcan throws std::invalid_argument with
  // it.
  std::optional<std::string> problem() const;
};
// Opens the device and the CAN channel (close, set the bitrate, ask for timestamps, open: see
// slcan_open_commands), and closes the channel again when destroyed, so no `slcand` or set-up
// script is needed. Throws CanSourceError when the device cannot be opened,
// std::invalid_argument for options that cannot be used (no device, an unsupported bitrate or
// baud).
std::unique_ptr<CanSource> open_slcan(const SlcanSourceOptions& options);

// Throws CanSourceError when the interface does not exist or the kernel has no CAN support.
std::unique_ptr<CanSource> open_socketcan(const std::string& interface);

struct CandumpSourceOptions {
  std::string file;
  // true: frames come at the pace they were recorded; false: as fast as they are read.
  bool recorded_timing = true;

  // Why these options cannot be used, naming the field ("file: empty; ..."); nullopt when they
  // can. open_candump throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};
// Reads the whole log first; throws std::invalid_argument for options that cannot be used,
// CandumpError naming the file and line of a bad line.
std::unique_ptr<CanSource> open_candump(const CandumpSourceOptions& options);

}  // namespace mocap::can
