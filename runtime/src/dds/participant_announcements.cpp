#include "dds/participant_announcements.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstring>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap {
namespace {

constexpr uint8_t kSubmessageData = 0x15;
constexpr uint32_t kSpdpWriter = 0x000100c2;
constexpr uint16_t kPidSentinel = 0x0001;
constexpr uint16_t kPidDomainId = 0x000f;
constexpr uint16_t kPidEntityName = 0x0062;
constexpr uint16_t kPidIdentityToken = 0x1001;

// Little or big endian, as each submessage's flag or the payload's encapsulation says.
struct Reader {
  std::span<const uint8_t> bytes;
  bool little = true;

  bool has(size_t offset, size_t size) const {
    return offset <= bytes.size() && size <= bytes.size() - offset;
  }
  uint16_t u16(size_t offset) const {
    return little ? static_cast<uint16_t>(bytes[offset] | bytes[offset + 1] << 8)
                  : static_cast<uint16_t>(bytes[offset] << 8 | bytes[offset + 1]);
  }
  uint32_t u32(size_t offset) const {
    uint32_t value = 0;
    for (int i = 0; i < 4; ++i) {
      const uint32_t byte = bytes[offset + static_cast<size_t>(i)];
      value |= little ? byte << (8 * i) : byte << (8 * (3 - i));
    }
    return value;
  }
};

std::string vendor_name(uint8_t major, uint8_t minor) {
  if (major == 0x01 && minor == 0x0f) return "eProsima Fast DDS";
  if (major == 0x01 && minor == 0x10) return "Eclipse Cyclone DDS";
  if (major == 0x01 && minor == 0x01) return "RTI Connext DDS";
  return fmt::format("vendor {:02x}{:02x}", major, minor);
}

// The participant's parameters from a serialized payload (encapsulation and parameter list).
bool read_parameters(std::span<const uint8_t> payload, AnnouncedParticipant& participant) {
  if (payload.size() < 4) return false;
  // PL_CDR_BE 0x0002, PL_CDR_LE 0x0003.
  if (payload[0] != 0x00 || (payload[1] != 0x02 && payload[1] != 0x03)) return false;
  Reader reader{payload, payload[1] == 0x03};
  size_t at = 4;
  while (reader.has(at, 4)) {
    const uint16_t id = reader.u16(at);
    const uint16_t length = reader.u16(at + 2);
    at += 4;
    if (id == kPidSentinel) return true;
    if (!reader.has(at, length)) return false;
    // The must-understand and vendor-specific bits are not part of the ids read here.
    const uint16_t pid = id & 0x3fff;
    if (pid == kPidEntityName && length >= 4) {
      const uint32_t size = reader.u32(at);
      if (size > 0 && size <= length - 4u) {
        const char* text = reinterpret_cast<const char*>(payload.data() + at + 4);
        participant.name.assign(text, strnlen(text, size));
      }
    } else if (pid == kPidDomainId && length >= 4) {
      participant.domain = static_cast<int>(reader.u32(at));
    } else if (pid == kPidIdentityToken) {
      participant.secure = true;
    }
    at += length;
  }
  return false;
}

}  // namespace

std::optional<AnnouncedParticipant> parse_participant_announcement(
    std::span<const uint8_t> packet) {
  if (packet.size() < 20 || std::memcmp(packet.data(), "RTPS", 4) != 0) return std::nullopt;
  AnnouncedParticipant participant;
  participant.vendor = vendor_name(packet[6], packet[7]);
  for (size_t i = 8; i < 20; ++i) participant.guid_prefix += fmt::format("{:02x}", packet[i]);
  size_t at = 20;
  while (at + 4 <= packet.size()) {
    const uint8_t id = packet[at];
    const uint8_t flags = packet[at + 1];
    Reader reader{packet, (flags & 0x01) != 0};
    const size_t length = reader.u16(at + 2);
    const size_t body = at + 4;
    // Length 0 on the last submessage means "to the end of the message".
    const size_t end = length == 0 ? packet.size() : body + length;
    if (end > packet.size()) return std::nullopt;
    if (id == kSubmessageData && end - body >= 20) {
      const uint16_t to_inline_qos = reader.u16(body + 2);
      // The writer's entity id is big-endian whatever the flags say (it is an octet array).
      const uint32_t writer = static_cast<uint32_t>(packet[body + 8]) << 24 |
                              static_cast<uint32_t>(packet[body + 9]) << 16 |
                              static_cast<uint32_t>(packet[body + 10]) << 8 | packet[body + 11];
      size_t payload = body + 4 + to_inline_qos;
      if (writer == kSpdpWriter && (flags & 0x04) != 0 && payload <= end) {
        if ((flags & 0x02) != 0) {  // inline QoS first: a parameter list up to its sentinel
          Reader inline_qos{packet, (flags & 0x01) != 0};
          while (payload + 4 <= end && inline_qos.u16(payload) != kPidSentinel) {
            payload += 4 + inline_qos.u16(payload + 2);
          }
          payload += 4;
        }
        if (payload <= end &&
            read_parameters(packet.subspan(payload, end - payload), participant)) {
          return participant;
        }
      }
    }
    if (length == 0) break;
    at = end;
  }
  return std::nullopt;
}

int discovery_multicast_port(int domain) { return 7400 + 250 * domain; }

std::vector<AnnouncedParticipant> listen_for_participants(const std::vector<int>& domains,
                                                          std::chrono::milliseconds duration) {
  std::vector<pollfd> sockets;
  std::vector<int> socket_domains;
  auto close_all = [&] {
    for (const pollfd& p : sockets) ::close(p.fd);
  };
  for (int domain : domains) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, IPPROTO_UDP);
    const int yes = 1;
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<uint16_t>(discovery_multicast_port(domain)));
    address.sin_addr.s_addr = htonl(INADDR_ANY);
    ip_mreq group{};
    group.imr_multiaddr.s_addr = inet_addr("239.255.0.1");
    group.imr_interface.s_addr = htonl(INADDR_ANY);
    if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes) != 0 ||
        setsockopt(fd, SOL_SOCKET, SO_REUSEPORT, &yes, sizeof yes) != 0 ||
        bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 ||
        setsockopt(fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &group, sizeof group) != 0) {
      const std::string why = std::strerror(errno);
      if (fd >= 0) ::close(fd);
      close_all();
      throw std::runtime_error(fmt::format("cannot listen on domain {}'s discovery port {}: {}",
                                           domain, discovery_multicast_port(domain), why));
    }
    sockets.push_back({fd, POLLIN, 0});
    socket_domains.push_back(domain);
  }
  std::map<std::string, AnnouncedParticipant> heard;
  const auto end = std::chrono::steady_clock::now() + duration;
  std::vector<uint8_t> buffer(65536);
  for (auto now = std::chrono::steady_clock::now(); now < end;
       now = std::chrono::steady_clock::now()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - now);
    if (::poll(sockets.data(), sockets.size(), static_cast<int>(left.count()) + 1) <= 0) continue;
    for (size_t s = 0; s < sockets.size(); ++s) {
      if ((sockets[s].revents & POLLIN) == 0) continue;
      sockaddr_in from{};
      socklen_t from_size = sizeof from;
      const ssize_t n = ::recvfrom(sockets[s].fd, buffer.data(), buffer.size(), MSG_DONTWAIT,
                                   reinterpret_cast<sockaddr*>(&from), &from_size);
      if (n <= 0) continue;
      auto participant = parse_participant_announcement({buffer.data(), static_cast<size_t>(n)});
      if (!participant) continue;
      if (participant->domain < 0) participant->domain = socket_domains[s];
      char text[INET_ADDRSTRLEN] = {};
      inet_ntop(AF_INET, &from.sin_addr, text, sizeof text);
      participant->address = text;
      heard[participant->guid_prefix] = *participant;
    }
  }
  close_all();
  std::vector<AnnouncedParticipant> participants;
  for (auto& [guid, participant] : heard) participants.push_back(std::move(participant));
  return participants;
}

}  // namespace mocap
