// Linux SocketCAN: frames from a CAN interface the kernel drives (can0 on a CAN HAT or PCIe
// card, slcan0 set up by slcand, vcan0 for tests) through a raw CAN socket.
#pragma once

#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>

#include <linux/can.h>

#include "common/can_io/can_frame.hpp"

namespace mocap::can {

class SocketCanError : public std::runtime_error {
 public:
  enum class Kind {
    kNoKernelSupport,  // the kernel has no CAN sockets (modules can, can_raw missing)
    kNoInterface,      // no such interface, or it is not a CAN interface
    kIo,               // anything else: the socket failed, the interface went down
  };
  SocketCanError(Kind kind, const std::string& message)
      : std::runtime_error(message), kind_(kind) {}
  // kNoKernelSupport and kNoInterface say that SocketCAN cannot be used on this machine as
  // configured, not that something broke.
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

// The frame the kernel delivered, as a CanFrame (stamp 0): flags CAN_EFF_FLAG and
// CAN_RTR_FLAG become `extended` and `remote`, the id loses them. A length above 8 (which the
// kernel never delivers on a classic CAN socket) is cut to 8.
CanFrame from_linux_frame(const struct can_frame& linux_frame);
// The kernel's form of `frame`. Throws std::invalid_argument for a frame that validate_frame
// refuses.
struct can_frame to_linux_frame(const CanFrame& frame);

// A raw CAN socket bound to one interface: receives every frame on the bus, sends frames.
// Closed when destroyed. Not thread-safe, but one thread may read while another writes.
class SocketCan {
 public:
  // Throws SocketCanError naming the interface and the reason: kNoKernelSupport ("CAN
  // sockets are not supported by this kernel ..."), kNoInterface ("CAN interface 'vcan0' not
  // found: No such device", or not a CAN interface), kIo for other failures.
  explicit SocketCan(std::string interface);
  ~SocketCan();
  SocketCan(SocketCan&& other) noexcept;
  SocketCan& operator=(SocketCan&& other) noexcept;
  SocketCan(const SocketCan&) = delete;
  SocketCan& operator=(const SocketCan&) = delete;

  // The next frame, waiting up to `timeout`; nullopt if none came. Its stamp is the kernel's
  // receive time (SO_TIMESTAMP; the time of the read if the kernel gives none). Throws
  // SocketCanError (kIo) naming the interface when it went down or away.
  std::optional<CanFrame> read(std::chrono::milliseconds timeout);
  // Sends `frame`. Throws std::invalid_argument for a frame that validate_frame refuses, and
  // SocketCanError (kIo) when the interface does not take it (down, transmit queue full).
  void write(const CanFrame& frame);

  const std::string& interface() const { return interface_; }
  // -1 after a move.
  int fd() const { return fd_; }

 private:
  std::string interface_;
  int fd_ = -1;
};

}  // namespace mocap::can
