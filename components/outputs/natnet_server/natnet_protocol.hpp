// NatNet, OptiTrack's streaming protocol, as a server speaks it: the packets a Motive host sends
// and the requests it reads, written from the protocol's public description (NatNet SDK 4.3's
// NatNetTypes.h, its PacketClient sample and its Python client).
//
// Every packet is one UDP datagram: a little-endian uint16 message id, a uint16 payload size
// and the payload. Strings end with a NUL; integers and floats are little-endian; positions are
// metres. The layout of a frame and of the descriptions depends on the bitstream version the
// client reads (3.0 to 4.2 here):
//   3.0   high-resolution stamps in the frame; no marker names in a body's description
//   4.0   marker names in a body's description
//   4.1   each frame section and each description preceded by its size in bytes; assets;
//         precision timestamps in the frame suffix
//   4.2   a body's description gives its orientation offset
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

namespace mocap::natnet {

constexpr uint16_t kDefaultCommandPort = 1510;
constexpr uint16_t kDefaultDataPort = 1511;
constexpr const char* kDefaultMulticastGroup = "239.255.42.99";
constexpr size_t kHeaderSize = 4;
// The largest payload a datagram carries (65535 less the IP, UDP and NatNet headers).
constexpr size_t kMaxPayload = 65503;

enum MessageId : uint16_t {
  kConnect = 0,
  kServerInfo = 1,
  kRequest = 2,
  kResponse = 3,
  kRequestModelDef = 4,
  kModelDef = 5,
  kRequestFrameOfData = 6,
  kFrameOfData = 7,
  kMessageString = 8,
  kDisconnect = 9,
  kKeepAlive = 10,
  kDisconnectByTimeout = 11,
  kEchoRequest = 12,
  kEchoResponse = 13,
  kDiscovery = 14,
  kUnrecognizedRequest = 100,
};

struct Version {
  uint8_t major = 0, minor = 0;

  // Whether this server writes this bitstream (3.0 to 4.2; 4.3 and later read as 4.2).
  bool supported() const;
  // 4.3 and later as 4.2, whose layout they share.
  Version written() const;
  bool at_least(uint8_t major_, uint8_t minor_) const {
    return major > major_ || (major == major_ && minor >= minor_);
  }
  friend bool operator==(const Version&, const Version&) = default;
};
constexpr Version kDefaultVersion{4, 1};

// "4.1" or "4.1.0.0" as a version; nullopt when it is neither.
std::optional<Version> parse_version(std::string_view text);

// --- requests ---------------------------------------------------------------------------------

struct Request {
  uint16_t id = 0;
  std::string payload;
};

// One datagram as a request, or nullopt and `problem` for what is not NatNet: fewer than 4
// bytes, a size field that disagrees with the datagram (a client may end its payload with one
// NUL more than it counts, as OptiTrack's samples do), or a message id no client sends.
std::optional<Request> parse_request(std::string_view datagram, std::string* problem);

// What a NAT_CONNECT asks for: the bitstream version in its connection options (sSender, then
// sConnectionOptions: a bool and four version bytes); nullopt when it names none (an empty
// connect, as libmotioncapture's, or version zero).
std::optional<Version> requested_version(const Request& connect);

// A NAT_REQUEST's command: its text up to the first NUL.
std::string command_text(const Request& request);

// --- what the server sends --------------------------------------------------------------------

struct ServerDescription {
  std::string application = "mocap-graph";
  uint8_t application_version[4] = {1, 0, 0, 0};
  Version natnet = kDefaultVersion;          // the bitstream this client is sent
  uint64_t clock_frequency = 1'000'000'000;  // ticks of the frame stamps per second
  uint16_t data_port = kDefaultDataPort;
  bool multicast = false;
  uint8_t multicast_group[4] = {239, 255, 42, 99};
};

struct MarkerSetDescription {
  std::string name;
  std::vector<std::string> marker_names;
};

struct RigidBodyDescription {
  std::string name;
  int32_t id = 0;
  int32_t parent_id = -1;
  Eigen::Vector3f offset = Eigen::Vector3f::Zero();
  Eigen::Quaternionf orientation_offset = Eigen::Quaternionf::Identity();
  std::vector<Eigen::Vector3f> markers;  // in the body's frame, metres
  std::vector<std::string> marker_names;
};

struct Descriptions {
  std::vector<MarkerSetDescription> marker_sets;
  std::vector<RigidBodyDescription> rigid_bodies;
};

struct MarkerSetData {
  std::string name;
  std::vector<Eigen::Vector3f> positions;
};

struct RigidBodyData {
  int32_t id = 0;
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Quaternionf orientation = Eigen::Quaternionf::Identity();
  float mean_error_m = 0;  // mean distance of its seen markers from where its pose puts them
  bool tracking_valid = false;
};

// Labeled-marker flags (NatNet 3.0 and later).
enum MarkerFlag : uint16_t {
  kOccluded = 0x01,
  kPointCloudSolved = 0x02,
  kModelSolved = 0x04,
  kHasModel = 0x08,
  kUnlabeled = 0x10,
  kActive = 0x20,
};

struct LabeledMarkerData {
  int32_t id = 0;  // model (a body's streaming id) in the high 16 bits, its marker in the low
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  float size_m = 0;
  uint16_t flags = 0;
  float residual_m = 0;
};

// The three high-resolution stamps, in ticks of ServerDescription::clock_frequency.
struct FrameStamps {
  uint64_t camera_mid_exposure = 0;
  uint64_t camera_data_received = 0;
  uint64_t transmit = 0;
};

struct FrameOfData {
  int32_t frame_number = 0;
  std::vector<MarkerSetData> marker_sets;
  std::vector<Eigen::Vector3f> other_markers;  // the legacy unlabeled list
  std::vector<RigidBodyData> rigid_bodies;
  std::vector<LabeledMarkerData> labeled_markers;
  uint32_t timecode = 0, timecode_subframe = 0;
  double timestamp_s = 0;
  FrameStamps stamps;
  bool tracked_models_changed = false;
};

// Packets, header included.
std::string encode_server_info(const ServerDescription& server);
std::string encode_descriptions(const Descriptions& descriptions, Version version);
// The frame as `version` lays it out.
std::string encode_frame(const FrameOfData& frame, Version version);
// What differs between two clients' copies of one frame packet of `version`: the transmit stamp,
// and the "bitstream version changed" flag of the first frame after a client's Bitstream command
// (OptiTrack's PacketClient skips frames until it sees it).
void set_transmit_stamp(std::string& frame_packet, Version version, uint64_t ticks);
void set_bitstream_changed(std::string& frame_packet, bool changed);
std::string encode_response(int32_t code);
std::string encode_response(float value);
std::string encode_response(std::string_view text);
std::string encode_message_string(std::string_view text);
std::string encode_unrecognized_request();
// NAT_ECHORESPONSE: the request's own stamp (its first 8 bytes) and the server's receive time.
std::string encode_echo_response(uint64_t request_stamp, uint64_t received_ticks);

}  // namespace mocap::natnet
