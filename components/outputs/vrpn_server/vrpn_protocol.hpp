// The VRPN wire protocol (vrpn/vrpn's Format_Of_Protocol.txt and vrpn_Connection.C), as much of
// it as a tracker server needs: the cookie both ends send first, the framing of every message,
// the descriptions that name senders and types, and vrpn_Tracker's position and velocity
// reports. Integers and doubles travel big-endian ("network order").
//
// A message is a 24-byte header (length, seconds, microseconds, sender, type, sequence number;
// each a 32-bit integer) and a payload padded with zeros to a multiple of 8 bytes. The length
// counts the header and the unpadded payload. Senders and types are numbered by each end for
// itself; a description (type -1 or -2) tells the other end which name a number stands for.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Geometry>

namespace mocap::vrpn {

constexpr uint16_t kDefaultPort = 3883;
constexpr size_t kCookieSize = 24;
constexpr size_t kHeaderSize = 24;

// The system message types this server reads or writes (-3, a UDP port, and -4, logging
// requests, it ignores: it sends over TCP only and logs nothing).
constexpr int32_t kSenderDescription = -1;
constexpr int32_t kTypeDescription = -2;

// The type names of the messages this server sends or answers.
constexpr std::string_view kPosQuatType = "vrpn_Tracker Pos_Quat";
constexpr std::string_view kVelocityType = "vrpn_Tracker Velocity";
constexpr std::string_view kPingType = "vrpn_Base ping_message";
constexpr std::string_view kPongType = "vrpn_Base pong_message";

// "vrpn: ver. 07.38  0" and zeros to 24 bytes: version 07.38, no remote logging asked.
std::string cookie();

enum class CookieCheck {
  Same,               // version 07.38
  OtherMinorVersion,  // 07.xx: compatible, as VRPN itself accepts it
  NotVrpn,            // another major version, or not VRPN at all
};
// The first 24 bytes of `bytes` (which must hold them) as the other end's cookie.
CookieCheck check_cookie(std::string_view bytes);

struct Message {
  int32_t sender = 0;
  int32_t type = 0;
  uint32_t seconds = 0;  // the time of what it reports, since the epoch
  uint32_t microseconds = 0;
  uint32_t sequence = 0;
  std::string payload;
};

// The message on the wire: header, payload, zeros to a multiple of 8.
std::string encode(const Message& message);

// A sender (kind kSenderDescription) or type (kTypeDescription) description of `id` as `name`:
// the name's length with its terminating NUL, the name, the NUL.
Message description(int32_t kind, int32_t id, std::string_view name);
// The name a description message gives, or nullopt when its payload is malformed.
std::optional<std::string> described_name(const Message& description);

// vrpn_Tracker's Pos_Quat payload: sensor, sensor again (for alignment), position (m), and the
// orientation as x, y, z, w.
std::string pos_quat_payload(int32_t sensor, const Eigen::Vector3d& position,
                             const Eigen::Quaterniond& orientation);
// vrpn_Tracker's Velocity payload: sensor twice, linear velocity (m/s), the rotation the body
// turns through in `dt` seconds (x, y, z, w), and dt.
std::string velocity_payload(int32_t sensor, const Eigen::Vector3d& velocity,
                             const Eigen::Quaterniond& rotation_in_dt, double dt);

// Messages out of a byte stream that arrives in pieces of any size. A length below the header's
// or above max_message_bytes makes the stream unreadable (error() says why): the caller closes
// it, since no later message boundary can be found.
class MessageReader {
 public:
  explicit MessageReader(size_t max_message_bytes = 1 << 16)
      : max_message_bytes_(max_message_bytes) {}

  void feed(std::string_view bytes) { buffer_.append(bytes); }
  // The next whole message, or nullopt until more bytes come (or after an error).
  std::optional<Message> next();
  const std::string& error() const { return error_; }
  size_t buffered_bytes() const { return buffer_.size() - read_; }

 private:
  size_t max_message_bytes_;
  std::string buffer_;
  size_t read_ = 0;
  std::string error_;
};

}  // namespace mocap::vrpn
