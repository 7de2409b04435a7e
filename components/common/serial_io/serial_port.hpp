// Serial devices in raw mode (a USB-CAN adaptor's /dev/ttyACM0, a USB2Dynamixel's
// /dev/ttyUSB0), and pseudo-terminals that stand in for them: a simulator (the PixArt box, the
// AX-12A servo chain) writes on a pty's master what the real device would send, and the
// driver reads and writes its slave side like any serial device.
#pragma once

#include <chrono>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::serial {

// A serial device that cannot be opened, configured, read or written, or went away; the
// message names the device and the system's reason.
class SerialError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The baud rates SerialPort accepts, ascending: 9600 to 115200, then 230400, 460800, 500000,
// 576000, 921600, 1000000, 2000000 and 3000000. (USB CDC adaptors ignore the rate; UART
// adaptors need the one they were set to.)
std::vector<int> supported_baud_rates();

struct SerialPortOptions {
  // Bits per second; one of supported_baud_rates().
  int baud_rate = 115200;
  // write_all gives up, with a SerialError, when the device takes no bytes for this long
  // (its buffer stays full: nobody reads the other end).
  std::chrono::milliseconds write_timeout{1000};
  // Drop what the device received before it was opened: old frames, the tail of a message
  // cut off by the previous run.
  bool discard_pending_input = true;

  // Why these options cannot be used, naming the field ("baud_rate: 12345 is not supported;
  // ..."); nullopt when they can. SerialPort's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// An open serial device in raw mode: 8 data bits, no parity, no echo, no line editing, no
// translation of '\r' or '\n', no flow control (software or hardware), modem lines ignored
// (CLOCAL). Non-blocking: reads wait in poll() for at most their timeout. Closed when
// destroyed. Not thread-safe, but one thread may read while another writes.
class SerialPort {
 public:
  // Opens `device` (O_NOCTTY: never becomes our controlling terminal; O_CLOEXEC). Throws
  // std::invalid_argument for options that cannot be used (an unsupported baud rate, a
  // negative timeout), and SerialError naming the device when it does not exist, cannot be
  // opened (permissions, in use), or is not a terminal.
  explicit SerialPort(std::string device, SerialPortOptions options = {});
  ~SerialPort();
  SerialPort(SerialPort&& other) noexcept;
  SerialPort& operator=(SerialPort&& other) noexcept;
  SerialPort(const SerialPort&) = delete;
  SerialPort& operator=(const SerialPort&) = delete;

  // Reads what has arrived, up to `size` bytes, waiting up to `timeout` for the first byte.
  // Returns the number of bytes read, 0 if none came in time. Throws SerialError when the
  // device went away (USB adaptor unplugged, pty master closed): poll reports a hang-up or an
  // error, read fails (EIO, ENXIO) or reports the end of the input.
  size_t read(char* buffer, size_t size, std::chrono::milliseconds timeout);
  // Writes all of `bytes`, waiting for room as needed. Throws SerialError naming the device
  // when it went away or took nothing for options.write_timeout.
  void write_all(std::string_view bytes);

  const std::string& device() const { return device_; }
  // The file descriptor, e.g. for the caller's own poll(); -1 after a move.
  int fd() const { return fd_; }

 private:
  std::string device_;
  SerialPortOptions options_;
  int fd_ = -1;
};

struct PseudoTerminalOptions {
  // write_all gives up, with a SerialError, when the pty takes no bytes for this long. Without
  // a reader on the slave side the pty buffers about 20 kB, then takes nothing more.
  std::chrono::milliseconds write_timeout{1000};

  // Why these options cannot be used, naming the field ("write_timeout: -1 ms is below 0");
  // nullopt when they can. PseudoTerminal's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// A pseudo-terminal pair: its master end stays here, its slave end (slave_path(), e.g.
// /dev/pts/3) is for someone else to open as a serial device. Raw mode, as SerialPort sets
// it, so bytes pass unchanged both ways. The master is closed when destroyed, which makes the
// slave path disappear and the slave's reader see a hang-up: an unplugged adaptor.
class PseudoTerminal {
 public:
  // Throws std::invalid_argument for options that cannot be used, SerialError when no
  // pseudo-terminal can be created.
  explicit PseudoTerminal(PseudoTerminalOptions options = {});
  ~PseudoTerminal();
  PseudoTerminal(PseudoTerminal&& other) noexcept;
  PseudoTerminal& operator=(PseudoTerminal&& other) noexcept;
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  // -1 after close_master().
  int master_fd() const { return master_fd_; }
  const std::string& slave_path() const { return slave_path_; }

  // Whether someone has the slave end open now. Bytes written while nobody does are kept
  // (up to the buffer's size) and read by the next one to open it.
  bool peer_connected() const;
  // Writes all of `bytes` on the master, for the slave's reader; waits for room as needed.
  // Throws SerialError when the pty takes nothing for options.write_timeout, or the master is
  // closed.
  void write_all(std::string_view bytes);
  // Reads what the slave's user wrote, up to `size` bytes, waiting up to `timeout` for the
  // first byte; 0 if none came. While nobody has the slave open it waits as well (a simulated
  // adaptor waits for its host). Throws SerialError after close_master().
  size_t read(char* buffer, size_t size, std::chrono::milliseconds timeout);
  // Closes the master: the slave's user sees its device hang up and the slave path vanish.
  void close_master();

 private:
  PseudoTerminalOptions options_;
  int master_fd_ = -1;
  std::string slave_path_;
};

}  // namespace mocap::serial
