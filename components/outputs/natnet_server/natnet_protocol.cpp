#include "outputs/natnet_server/natnet_protocol.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>

#include <fmt/format.h>

namespace mocap::natnet {
namespace {

// sSender: the application's name in 256 bytes and two four-byte versions.
constexpr size_t kNameLength = 256;
constexpr size_t kSenderSize = kNameLength + 4 + 4;

class Writer {
 public:
  template <typename T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));  // every platform this builds on is little-endian
    out_.append(bytes, sizeof(T));
  }
  void put(const Eigen::Vector3f& v) {
    for (int i = 0; i < 3; ++i) put(v[i]);
  }
  void put(const Eigen::Quaternionf& q) {
    put(q.x());
    put(q.y());
    put(q.z());
    put(q.w());
  }
  void put_string(std::string_view text) {
    out_.append(text.substr(0, text.find('\0')));
    out_.push_back('\0');
  }
  void put_bytes(const void* data, size_t size) {
    out_.append(static_cast<const char*>(data), size);
  }
  size_t size() const { return out_.size(); }

  // Reserves an int32 filled in later (a count or a section's size).
  size_t reserve_int() {
    put(int32_t{0});
    return out_.size() - 4;
  }
  void fill_int(size_t at, int32_t value) { std::memcpy(&out_[at], &value, 4); }

  // NatNet 4.1's section size: the bytes after it, up to the end of the section.
  struct Section {
    size_t size_at = 0;
    bool sized = false;
  };
  Section begin_section(Version version) {
    if (!version.at_least(4, 1)) return {};
    return {reserve_int(), true};
  }
  void end_section(const Section& section) {
    if (section.sized) {
      fill_int(section.size_at, static_cast<int32_t>(out_.size() - section.size_at - 4));
    }
  }

  // The packet: header with the payload's size, then the payload.
  std::string packet(uint16_t id) && {
    std::string packet(kHeaderSize, '\0');
    const auto size = static_cast<uint16_t>(std::min(out_.size(), size_t{0xFFFF}));
    std::memcpy(&packet[0], &id, 2);
    std::memcpy(&packet[2], &size, 2);
    return packet + out_;
  }

 private:
  std::string out_;
};

template <typename T>
int32_t count(const std::vector<T>& items) {
  return static_cast<int32_t>(items.size());
}

void put_rigid_body(Writer& out, const RigidBodyData& body) {
  out.put(body.id);
  out.put(body.position);
  out.put(body.orientation);
  out.put(body.mean_error_m);
  out.put(static_cast<int16_t>(body.tracking_valid ? 0x01 : 0x00));
}

void put_rigid_body_description(Writer& out, const RigidBodyDescription& body, Version version) {
  out.put_string(body.name);
  out.put(body.id);
  out.put(body.parent_id);
  out.put(body.offset);
  if (version.at_least(4, 2)) out.put(body.orientation_offset);
  out.put(count(body.markers));
  for (const Eigen::Vector3f& marker : body.markers) out.put(marker);
  for (size_t i = 0; i < body.markers.size(); ++i) out.put(int32_t{0});  // no active labels
  if (version.at_least(4, 0)) {
    for (size_t i = 0; i < body.markers.size(); ++i) {
      out.put_string(i < body.marker_names.size() ? body.marker_names[i] : std::string());
    }
  }
}

}  // namespace

bool Version::supported() const { return at_least(3, 0); }

Version Version::written() const { return at_least(4, 2) ? Version{4, 2} : *this; }

std::optional<Version> parse_version(std::string_view text) {
  int parts[4] = {0, 0, 0, 0};
  size_t part = 0;
  const char* p = text.data();
  const char* end = text.data() + text.size();
  while (part < 4) {
    const auto [next, error] = std::from_chars(p, end, parts[part]);
    if (error != std::errc() || parts[part] < 0 || parts[part] > 255) return std::nullopt;
    ++part;
    p = next;
    if (p == end) break;
    if (*p != '.') return std::nullopt;
    ++p;
  }
  if (p != end || part < 2) return std::nullopt;
  return Version{static_cast<uint8_t>(parts[0]), static_cast<uint8_t>(parts[1])};
}

std::optional<Request> parse_request(std::string_view datagram, std::string* problem) {
  auto fail = [&](std::string text) -> std::optional<Request> {
    if (problem) *problem = std::move(text);
    return std::nullopt;
  };
  if (datagram.size() < kHeaderSize) {
    return fail(fmt::format("{} bytes: shorter than a NatNet header", datagram.size()));
  }
  Request request;
  uint16_t size = 0;
  std::memcpy(&request.id, datagram.data(), 2);
  std::memcpy(&size, datagram.data() + 2, 2);
  const size_t payload = datagram.size() - kHeaderSize;
  if (payload != size && payload != size + size_t{1}) {
    return fail(fmt::format("message {} says {} payload bytes, the datagram holds {}", request.id,
                            size, payload));
  }
  switch (request.id) {
    case kServerInfo:
    case kResponse:
    case kModelDef:
    case kFrameOfData:
    case kMessageString:
    case kDisconnectByTimeout:
    case kEchoResponse:
      return fail(fmt::format("message id {} is no NatNet request", request.id));
    default:
      // A request of a later version than this server's is answered as unrecognized.
      if (request.id >= kUnrecognizedRequest) {
        return fail(fmt::format("message id {} is no NatNet request", request.id));
      }
  }
  request.payload.assign(datagram.substr(kHeaderSize, size));
  return request;
}

std::optional<Version> requested_version(const Request& connect) {
  constexpr size_t kVersionAt = kSenderSize + 1;  // after subscribedDataOnly
  if (connect.payload.size() < kVersionAt + 2) return std::nullopt;
  const Version version{static_cast<uint8_t>(connect.payload[kVersionAt]),
                        static_cast<uint8_t>(connect.payload[kVersionAt + 1])};
  if (version.major == 0 && version.minor == 0) return std::nullopt;
  return version;
}

std::string command_text(const Request& request) {
  return request.payload.substr(0, request.payload.find('\0'));
}

std::string encode_server_info(const ServerDescription& server) {
  Writer out;
  char name[kNameLength] = {};
  std::memcpy(name, server.application.data(),
              std::min(server.application.size(), kNameLength - 1));
  out.put_bytes(name, kNameLength);
  out.put_bytes(server.application_version, 4);
  const uint8_t natnet[4] = {server.natnet.major, server.natnet.minor, 0, 0};
  out.put_bytes(natnet, 4);
  out.put(server.clock_frequency);
  out.put(server.data_port);
  out.put(static_cast<uint8_t>(server.multicast ? 1 : 0));
  out.put_bytes(server.multicast_group, 4);
  return std::move(out).packet(kServerInfo);
}

std::string encode_descriptions(const Descriptions& descriptions, Version version) {
  version = version.written();
  Writer out;
  out.put(count(descriptions.marker_sets) + count(descriptions.rigid_bodies));
  for (const MarkerSetDescription& set : descriptions.marker_sets) {
    out.put(int32_t{0});  // Descriptor_MarkerSet
    const Writer::Section section = out.begin_section(version);
    out.put_string(set.name);
    out.put(count(set.marker_names));
    for (const std::string& name : set.marker_names) out.put_string(name);
    out.end_section(section);
  }
  for (const RigidBodyDescription& body : descriptions.rigid_bodies) {
    out.put(int32_t{1});  // Descriptor_RigidBody
    const Writer::Section section = out.begin_section(version);
    put_rigid_body_description(out, body, version);
    out.end_section(section);
  }
  return std::move(out).packet(kModelDef);
}

std::string encode_frame(const FrameOfData& frame, Version version) {
  version = version.written();
  Writer out;
  out.put(frame.frame_number);

  out.put(count(frame.marker_sets));
  Writer::Section section = out.begin_section(version);
  for (const MarkerSetData& set : frame.marker_sets) {
    out.put_string(set.name);
    out.put(count(set.positions));
    for (const Eigen::Vector3f& p : set.positions) out.put(p);
  }
  out.end_section(section);

  out.put(count(frame.other_markers));
  section = out.begin_section(version);
  for (const Eigen::Vector3f& p : frame.other_markers) out.put(p);
  out.end_section(section);

  out.put(count(frame.rigid_bodies));
  section = out.begin_section(version);
  for (const RigidBodyData& body : frame.rigid_bodies) put_rigid_body(out, body);
  out.end_section(section);

  out.put(int32_t{0});  // skeletons
  out.end_section(out.begin_section(version));
  if (version.at_least(4, 1)) {
    out.put(int32_t{0});  // assets
    out.end_section(out.begin_section(version));
  }

  out.put(count(frame.labeled_markers));
  section = out.begin_section(version);
  for (const LabeledMarkerData& marker : frame.labeled_markers) {
    out.put(marker.id);
    out.put(marker.position);
    out.put(marker.size_m);
    out.put(static_cast<int16_t>(marker.flags));
    out.put(marker.residual_m);
  }
  out.end_section(section);

  out.put(int32_t{0});  // force plates
  out.end_section(out.begin_section(version));
  out.put(int32_t{0});  // devices
  out.end_section(out.begin_section(version));

  out.put(frame.timecode);
  out.put(frame.timecode_subframe);
  out.put(frame.timestamp_s);
  out.put(frame.stamps.camera_mid_exposure);
  out.put(frame.stamps.camera_data_received);
  out.put(frame.stamps.transmit);
  if (version.at_least(4, 1)) {
    out.put(uint32_t{0});  // precision timestamp: no PTP-disciplined clock behind the cameras
    out.put(uint32_t{0});
  }
  out.put(static_cast<int16_t>(frame.tracked_models_changed ? 0x02 : 0x00));
  out.put(int32_t{0});  // end of data
  return std::move(out).packet(kFrameOfData);
}

// A frame packet ends with the transmit stamp, [the precision stamp (4.1+)], params (int16) and
// the end-of-data tag (int32).
constexpr size_t kParamsFromEnd = 2 + 4;

void set_transmit_stamp(std::string& frame_packet, Version version, uint64_t ticks) {
  const size_t from_end = 8 + (version.written().at_least(4, 1) ? 8 : 0) + kParamsFromEnd;
  std::memcpy(&frame_packet[frame_packet.size() - from_end], &ticks, 8);
}

void set_bitstream_changed(std::string& frame_packet, bool changed) {
  constexpr char kBitstreamChanged = 0x08;
  char& low_byte = frame_packet[frame_packet.size() - kParamsFromEnd];
  low_byte =
      static_cast<char>(changed ? low_byte | kBitstreamChanged : low_byte & ~kBitstreamChanged);
}

std::string encode_response(int32_t code) {
  Writer out;
  out.put(code);
  return std::move(out).packet(kResponse);
}

std::string encode_response(float value) {
  Writer out;
  out.put(value);
  return std::move(out).packet(kResponse);
}

std::string encode_response(std::string_view text) {
  Writer out;
  out.put_string(text);
  return std::move(out).packet(kResponse);
}

std::string encode_message_string(std::string_view text) {
  Writer out;
  out.put_string(text);
  return std::move(out).packet(kMessageString);
}

std::string encode_unrecognized_request() { return Writer().packet(kUnrecognizedRequest); }

std::string encode_echo_response(uint64_t request_stamp, uint64_t received_ticks) {
  Writer out;
  out.put(request_stamp);
  out.put(received_ticks);
  return std::move(out).packet(kEchoResponse);
}

}  // namespace mocap::natnet
