#include "common/can_io/socketcan.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <utility>

#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <fmt/format.h>

namespace mocap::can {
namespace {

using SteadyClock = std::chrono::steady_clock;

int64_t realtime_now_ns() {
  timespec now{};
  ::clock_gettime(CLOCK_REALTIME, &now);
  return static_cast<int64_t>(now.tv_sec) * 1'000'000'000 + now.tv_nsec;
}

// The SO_TIMESTAMP receive time in `message`, nanoseconds since the epoch; 0 if absent.
int64_t receive_stamp_ns(msghdr& message) {
  for (cmsghdr* header = CMSG_FIRSTHDR(&message); header != nullptr;
       header = CMSG_NXTHDR(&message, header)) {
    if (header->cmsg_level == SOL_SOCKET && header->cmsg_type == SCM_TIMESTAMP) {
      timeval stamp{};
      std::memcpy(&stamp, CMSG_DATA(header), sizeof(stamp));
      return static_cast<int64_t>(stamp.tv_sec) * 1'000'000'000 +
             static_cast<int64_t>(stamp.tv_usec) * 1000;
    }
  }
  return 0;
}

}  // namespace

CanFrame from_linux_frame(const struct can_frame& linux_frame) {
  CanFrame frame;
  frame.extended = (linux_frame.can_id & CAN_EFF_FLAG) != 0;
  frame.remote = (linux_frame.can_id & CAN_RTR_FLAG) != 0;
  frame.id = linux_frame.can_id & (frame.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  // `len` is the field older headers call can_dlc.
  frame.length = std::min<uint8_t>(linux_frame.len, kMaxDataLength);
  if (!frame.remote) std::copy_n(linux_frame.data, frame.length, frame.data.begin());
  return frame;
}

struct can_frame to_linux_frame(const CanFrame& frame) {
  validate_frame(frame);
  struct can_frame linux_frame {};
  linux_frame.can_id = frame.id;
  if (frame.extended) linux_frame.can_id |= CAN_EFF_FLAG;
  if (frame.remote) linux_frame.can_id |= CAN_RTR_FLAG;
  linux_frame.len = frame.length;
  if (!frame.remote) std::copy_n(frame.data.begin(), frame.length, linux_frame.data);
  return linux_frame;
}

SocketCan::SocketCan(std::string interface) : interface_(std::move(interface)) {
  using Kind = SocketCanError::Kind;
  fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) {
    const int error_number = errno;
    if (error_number == EAFNOSUPPORT || error_number == EPROTONOSUPPORT) {
      throw SocketCanError(
          Kind::kNoKernelSupport,
          fmt::format("CAN sockets are not supported by this kernel (socket(PF_CAN, SOCK_RAW, "
                      "CAN_RAW): {}); CAN interface '{}' cannot be used: the kernel needs the "
                      "can and can_raw modules",
                      std::strerror(error_number), interface_));
    }
    throw SocketCanError(Kind::kIo, fmt::format("cannot open a CAN socket for '{}': {}", interface_,
                                                std::strerror(error_number)));
  }
  try {
    const unsigned index = ::if_nametoindex(interface_.c_str());
    if (index == 0) {
      throw SocketCanError(Kind::kNoInterface, fmt::format("CAN interface '{}' not found: {}",
                                                           interface_, std::strerror(errno)));
    }
    const int enable = 1;
    if (::setsockopt(fd_, SOL_SOCKET, SO_TIMESTAMP, &enable, sizeof(enable)) != 0) {
      throw SocketCanError(Kind::kIo, fmt::format("CAN interface '{}': cannot enable receive "
                                                  "timestamps: {}",
                                                  interface_, std::strerror(errno)));
    }
    sockaddr_can address{};
    address.can_family = AF_CAN;
    address.can_ifindex = static_cast<int>(index);
    if (::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
      const int error_number = errno;
      if (error_number == ENODEV) {
        throw SocketCanError(Kind::kNoInterface,
                             fmt::format("interface '{}' is not a CAN interface (bind: {})",
                                         interface_, std::strerror(error_number)));
      }
      throw SocketCanError(Kind::kIo, fmt::format("cannot bind a CAN socket to '{}': {}",
                                                  interface_, std::strerror(error_number)));
    }
  } catch (...) {
    ::close(std::exchange(fd_, -1));
    throw;
  }
}

SocketCan::~SocketCan() {
  if (fd_ >= 0) ::close(fd_);
}

SocketCan::SocketCan(SocketCan&& other) noexcept
    : interface_(std::move(other.interface_)), fd_(std::exchange(other.fd_, -1)) {}

SocketCan& SocketCan::operator=(SocketCan&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    interface_ = std::move(other.interface_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

std::optional<CanFrame> SocketCan::read(std::chrono::milliseconds timeout) {
  using Kind = SocketCanError::Kind;
  const auto deadline = SteadyClock::now() + timeout;
  while (true) {
    const auto left =
        std::chrono::ceil<std::chrono::milliseconds>(deadline - SteadyClock::now()).count();
    pollfd entry{fd_, POLLIN, 0};
    const int ready = ::poll(&entry, 1, static_cast<int>(std::max<decltype(left)>(left, 0)));
    if (ready == 0) return std::nullopt;
    if (ready < 0) {
      if (errno == EINTR) continue;
      throw SocketCanError(Kind::kIo, fmt::format("CAN interface '{}': poll failed: {}", interface_,
                                                  std::strerror(errno)));
    }
    struct can_frame linux_frame {};
    iovec data{&linux_frame, sizeof(linux_frame)};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timeval))];
    msghdr message{};
    message.msg_iov = &data;
    message.msg_iovlen = 1;
    message.msg_control = control;
    message.msg_controllen = sizeof(control);
    const ssize_t count = ::recvmsg(fd_, &message, 0);
    if (count < 0) {
      if (errno == EAGAIN || errno == EINTR) continue;
      throw SocketCanError(Kind::kIo, fmt::format("cannot read from CAN interface '{}': {}",
                                                  interface_, std::strerror(errno)));
    }
    if (static_cast<size_t>(count) != sizeof(linux_frame)) {
      throw SocketCanError(Kind::kIo,
                           fmt::format("CAN interface '{}' delivered {} bytes, not a classic "
                                       "CAN frame ({} bytes)",
                                       interface_, count, sizeof(linux_frame)));
    }
    CanFrame frame = from_linux_frame(linux_frame);
    frame.stamp_ns = receive_stamp_ns(message);
    if (frame.stamp_ns == 0) frame.stamp_ns = realtime_now_ns();
    return frame;
  }
}

void SocketCan::write(const CanFrame& frame) {
  const struct can_frame linux_frame = to_linux_frame(frame);
  while (true) {
    const ssize_t count = ::write(fd_, &linux_frame, sizeof(linux_frame));
    if (count == static_cast<ssize_t>(sizeof(linux_frame))) return;
    if (count < 0 && errno == EINTR) continue;
    const std::string reason = count < 0 ? std::strerror(errno) : "short write";
    throw SocketCanError(SocketCanError::Kind::kIo,
                         fmt::format("cannot send {} on CAN interface '{}': {}", to_string(frame),
                                     interface_, reason));
  }
}

}  // namespace mocap::can
