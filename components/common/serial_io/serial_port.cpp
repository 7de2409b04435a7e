#include "common/serial_io/serial_port.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <fmt/format.h>

namespace mocap::serial {
namespace {

using SteadyClock = std::chrono::steady_clock;

// While the other end of a pty is absent, poll() reports a hang-up at once instead of
// waiting; the master's reader and writer then wait in steps of this much for it to return.
constexpr std::chrono::milliseconds kAbsentPeerPause{5};

constexpr std::array<std::pair<int, speed_t>, 13> kBaudRates{{{9600, B9600},
                                                              {19200, B19200},
                                                              {38400, B38400},
                                                              {57600, B57600},
                                                              {115200, B115200},
                                                              {230400, B230400},
                                                              {460800, B460800},
                                                              {500000, B500000},
                                                              {576000, B576000},
                                                              {921600, B921600},
                                                              {1000000, B1000000},
                                                              {2000000, B2000000},
                                                              {3000000, B3000000}}};

// The termios constant of a baud rate; nullopt for one not in kBaudRates.
std::optional<speed_t> baud_constant(int baud_rate) {
  for (const auto& [rate, constant] : kBaudRates) {
    if (rate == baud_rate) return constant;
  }
  return std::nullopt;
}

std::string system_error_text(int error_number) { return std::strerror(error_number); }

// The time left until `deadline`, rounded up to whole milliseconds for poll(); 0 if past.
int remaining_ms(SteadyClock::time_point deadline) {
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - SteadyClock::now());
  return static_cast<int>(std::max<std::chrono::milliseconds::rep>(left.count(), 0));
}

// poll() on one descriptor until something happens or `deadline` passes (one poll with
// timeout 0 if it already has). Returns revents: 0 on timeout. Retries after signals.
short poll_until(int fd, short events, SteadyClock::time_point deadline, const std::string& name) {
  while (true) {
    pollfd entry{fd, events, 0};
    const int ready = ::poll(&entry, 1, remaining_ms(deadline));
    if (ready > 0) return entry.revents;
    if (ready == 0) return 0;
    if (errno != EINTR) {
      throw SerialError(fmt::format("{}: poll failed: {}", name, system_error_text(errno)));
    }
  }
}

void set_raw_mode(int fd, const std::string& name, speed_t speed) {
  termios settings{};
  if (::tcgetattr(fd, &settings) != 0) {
    const int error_number = errno;
    if (error_number == ENOTTY) {
      throw SerialError(fmt::format("{} is not a serial device (tcgetattr: {})", name,
                                    system_error_text(error_number)));
    }
    throw SerialError(fmt::format("{}: cannot read the terminal settings: {}", name,
                                  system_error_text(error_number)));
  }
  ::cfmakeraw(&settings);
  settings.c_cflag |= CLOCAL | CREAD;
  settings.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS | CSTOPB);
  settings.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  // Reads return at once with what is there; read() waits in poll() instead.
  settings.c_cc[VMIN] = 0;
  settings.c_cc[VTIME] = 0;
  if (::cfsetispeed(&settings, speed) != 0 || ::cfsetospeed(&settings, speed) != 0 ||
      ::tcsetattr(fd, TCSANOW, &settings) != 0) {
    throw SerialError(
        fmt::format("{}: cannot set raw mode and baud rate: {}", name, system_error_text(errno)));
  }
}

void close_quietly(int fd) {
  if (fd >= 0) ::close(fd);
}

}  // namespace

std::vector<int> supported_baud_rates() {
  std::vector<int> rates;
  for (const auto& [rate, constant] : kBaudRates) rates.push_back(rate);
  return rates;
}

// --- SerialPort ------------------------------------------------------------------------------

std::optional<std::string> SerialPortOptions::problem() const {
  if (!baud_constant(baud_rate)) {
    std::string supported;
    for (int rate : supported_baud_rates()) {
      supported += (supported.empty() ? "" : ", ") + std::to_string(rate);
    }
    return fmt::format("baud_rate: {} is not supported; supported: {}", baud_rate, supported);
  }
  if (write_timeout.count() < 0) {
    return fmt::format("write_timeout: {} ms is below 0", write_timeout.count());
  }
  return std::nullopt;
}

SerialPort::SerialPort(std::string device, SerialPortOptions options)
    : device_(std::move(device)), options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("SerialPortOptions::" + *problem);
  }
  const speed_t speed = *baud_constant(options_.baud_rate);
  fd_ = ::open(device_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    throw SerialError(
        fmt::format("cannot open serial device {}: {}", device_, system_error_text(errno)));
  }
  try {
    set_raw_mode(fd_, device_, speed);
  } catch (...) {
    close_quietly(std::exchange(fd_, -1));
    throw;
  }
  if (options_.discard_pending_input) ::tcflush(fd_, TCIFLUSH);
}

SerialPort::~SerialPort() { close_quietly(fd_); }

SerialPort::SerialPort(SerialPort&& other) noexcept
    : device_(std::move(other.device_)),
      options_(other.options_),
      fd_(std::exchange(other.fd_, -1)) {}

SerialPort& SerialPort::operator=(SerialPort&& other) noexcept {
  if (this != &other) {
    close_quietly(fd_);
    device_ = std::move(other.device_);
    options_ = other.options_;
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

size_t SerialPort::read(char* buffer, size_t size, std::chrono::milliseconds timeout) {
  if (fd_ < 0) throw SerialError("read from a moved-from SerialPort");
  if (size == 0) return 0;
  const auto deadline = SteadyClock::now() + timeout;
  while (true) {
    const short events = poll_until(fd_, POLLIN, deadline, device_);
    if (events == 0) return 0;
    if (events & POLLNVAL) throw SerialError(fmt::format("{}: descriptor not open", device_));
    const ssize_t count = ::read(fd_, buffer, size);
    if (count > 0) return static_cast<size_t>(count);
    const bool hung_up = (events & (POLLHUP | POLLERR)) != 0;
    if (count < 0 && (errno == EAGAIN || errno == EINTR) && !hung_up) continue;
    if (count < 0 && errno != EAGAIN && errno != EINTR) {
      throw SerialError(fmt::format("serial device {} failed or went away: {}", device_,
                                    system_error_text(errno)));
    }
    // With VMIN = VTIME = 0 a terminal reports no data as 0 bytes, but poll() said there was
    // something to read: only a hung-up device ends up here.
    throw SerialError(fmt::format("serial device {} hung up (unplugged or closed)", device_));
  }
}

void SerialPort::write_all(std::string_view bytes) {
  if (fd_ < 0) throw SerialError("write to a moved-from SerialPort");
  const auto deadline = SteadyClock::now() + options_.write_timeout;
  const size_t total = bytes.size();
  while (!bytes.empty()) {
    const ssize_t count = ::write(fd_, bytes.data(), bytes.size());
    if (count > 0) {
      bytes.remove_prefix(static_cast<size_t>(count));
      continue;
    }
    if (count < 0 && errno != EAGAIN && errno != EINTR) {
      throw SerialError(
          fmt::format("cannot write to serial device {}: {}", device_, system_error_text(errno)));
    }
    const short events = poll_until(fd_, POLLOUT, deadline, device_);
    if (events == 0) {
      throw SerialError(fmt::format("serial device {} took {} of {} bytes in {} ms", device_,
                                    total - bytes.size(), total, options_.write_timeout.count()));
    }
    if (events & (POLLHUP | POLLERR | POLLNVAL)) {
      throw SerialError(fmt::format("serial device {} hung up (unplugged or closed)", device_));
    }
  }
}

// --- PseudoTerminal --------------------------------------------------------------------------

std::optional<std::string> PseudoTerminalOptions::problem() const {
  if (write_timeout.count() < 0) {
    return fmt::format("write_timeout: {} ms is below 0", write_timeout.count());
  }
  return std::nullopt;
}

PseudoTerminal::PseudoTerminal(PseudoTerminalOptions options) : options_(options) {
  if (auto problem = options_.problem()) {
    throw std::invalid_argument("PseudoTerminalOptions::" + *problem);
  }
  master_fd_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (master_fd_ < 0) {
    throw SerialError(fmt::format("cannot create a pseudo-terminal: {}", system_error_text(errno)));
  }
  try {
    std::array<char, 128> name{};
    if (::grantpt(master_fd_) != 0 || ::unlockpt(master_fd_) != 0 ||
        ::ptsname_r(master_fd_, name.data(), name.size()) != 0) {
      throw SerialError(
          fmt::format("cannot set up a pseudo-terminal: {}", system_error_text(errno)));
    }
    slave_path_ = name.data();
    // Raw mode on the master sets the line discipline both ends share: without it the pty
    // would echo the simulator's bytes back to it and turn '\r' into '\n'.
    set_raw_mode(master_fd_, "pseudo-terminal master of " + slave_path_, B115200);
    // Until its slave end has been opened and closed once, a pty master reports neither a
    // hang-up nor an error when nobody is there; do it now, so that "nobody has the slave
    // open" looks the same before the first peer as after the last.
    const int slave = ::open(slave_path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (slave < 0) {
      throw SerialError(fmt::format("cannot open {}: {}", slave_path_, system_error_text(errno)));
    }
    ::close(slave);
  } catch (...) {
    close_quietly(std::exchange(master_fd_, -1));
    throw;
  }
}

PseudoTerminal::~PseudoTerminal() { close_quietly(master_fd_); }

PseudoTerminal::PseudoTerminal(PseudoTerminal&& other) noexcept
    : options_(other.options_),
      master_fd_(std::exchange(other.master_fd_, -1)),
      slave_path_(std::move(other.slave_path_)) {}

PseudoTerminal& PseudoTerminal::operator=(PseudoTerminal&& other) noexcept {
  if (this != &other) {
    close_quietly(master_fd_);
    options_ = other.options_;
    master_fd_ = std::exchange(other.master_fd_, -1);
    slave_path_ = std::move(other.slave_path_);
  }
  return *this;
}

bool PseudoTerminal::peer_connected() const {
  if (master_fd_ < 0) return false;
  pollfd entry{master_fd_, 0, 0};
  return ::poll(&entry, 1, 0) == 0 || !(entry.revents & POLLHUP);
}

void PseudoTerminal::write_all(std::string_view bytes) {
  if (master_fd_ < 0) {
    throw SerialError(fmt::format("pseudo-terminal {}: the master is closed", slave_path_));
  }
  const std::string name = "pseudo-terminal master of " + slave_path_;
  const auto deadline = SteadyClock::now() + options_.write_timeout;
  const size_t total = bytes.size();
  while (!bytes.empty()) {
    const ssize_t count = ::write(master_fd_, bytes.data(), bytes.size());
    if (count > 0) {
      bytes.remove_prefix(static_cast<size_t>(count));
      continue;
    }
    if (count < 0 && errno != EAGAIN && errno != EINTR) {
      throw SerialError(fmt::format("cannot write to {}: {}", name, system_error_text(errno)));
    }
    const short events = poll_until(master_fd_, POLLOUT, deadline, name);
    if (events == 0 || SteadyClock::now() >= deadline) {
      throw SerialError(fmt::format("{} took {} of {} bytes in {} ms (nobody reading?)", name,
                                    total - bytes.size(), total, options_.write_timeout.count()));
    }
    // Full, and nobody has the slave open: poll() reports the hang-up at once; wait for a
    // reader instead of spinning.
    if (!(events & POLLOUT)) std::this_thread::sleep_for(kAbsentPeerPause);
  }
}

size_t PseudoTerminal::read(char* buffer, size_t size, std::chrono::milliseconds timeout) {
  if (master_fd_ < 0) {
    throw SerialError(fmt::format("pseudo-terminal {}: the master is closed", slave_path_));
  }
  if (size == 0) return 0;
  const std::string name = "pseudo-terminal master of " + slave_path_;
  const auto deadline = SteadyClock::now() + timeout;
  while (true) {
    const short events = poll_until(master_fd_, POLLIN, deadline, name);
    if (events == 0) return 0;
    const ssize_t count = ::read(master_fd_, buffer, size);
    if (count > 0) return static_cast<size_t>(count);
    // EIO: nobody has the slave open (it was closed, or has not been opened again yet).
    if (count < 0 && errno != EAGAIN && errno != EINTR && errno != EIO) {
      throw SerialError(fmt::format("cannot read from {}: {}", name, system_error_text(errno)));
    }
    if (SteadyClock::now() >= deadline) return 0;
    if (events & POLLHUP) {
      std::this_thread::sleep_for(
          std::min(kAbsentPeerPause,
                   std::chrono::ceil<std::chrono::milliseconds>(deadline - SteadyClock::now())));
    }
  }
}

void PseudoTerminal::close_master() { close_quietly(std::exchange(master_fd_, -1)); }

}  // namespace mocap::serial
