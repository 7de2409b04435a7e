// Participants as they announce themselves on the wire, whatever their DDS implementation and
// domain, and whether or not this process could talk to them: RTPS's participant discovery
// (SPDP) messages, read off the domain's discovery multicast group (239.255.0.1, port
// 7400 + 250 x domain; the RTPS 2.x specification, 9.6.1). A doctor uses them to find a graph
// started on another domain, and participants that use DDS Security, whose topics a
// participant without credentials never sees.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace mocap {

struct AnnouncedParticipant {
  std::string guid_prefix;  // 24 hex digits: one participant
  std::string name;         // its entity name (ours: the group); empty when it gives none
  int domain = -1;          // announced, else that of the port it was heard on
  bool secure = false;      // carries DDS Security's identity token
  std::string vendor;       // "eProsima Fast DDS", "Eclipse Cyclone DDS", or the id in hex
  std::string address;      // the sender's IPv4 address
};

// The participant an SPDP DATA submessage of `packet` announces; nullopt for any other RTPS
// message, and for bytes that are not RTPS. Never reads past `packet`.
std::optional<AnnouncedParticipant> parse_participant_announcement(std::span<const uint8_t> packet);

// The discovery multicast port of `domain`.
int discovery_multicast_port(int domain);

// Listens on the discovery port of each of `domains` for `duration` and returns every
// participant heard (the latest announcement of each). Throws std::runtime_error when a port
// cannot be opened.
std::vector<AnnouncedParticipant> listen_for_participants(const std::vector<int>& domains,
                                                          std::chrono::milliseconds duration);

}  // namespace mocap
