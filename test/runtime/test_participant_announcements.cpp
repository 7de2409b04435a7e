// Participants' announcements (SPDP) read off the wire: messages laid out by hand from the RTPS
// 2.x specification (8.3 and 9.4: the header, submessages, DATA, ParameterLists; 9.6.2.2: the
// parameter ids), and one heard from a real participant of this build.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "dds/dds_transport.hpp"
#include "dds/participant_announcements.hpp"
#include "host/dds_implementations.hpp"
#include "test/test_support.hpp"

namespace mocap {
namespace {

struct Bytes {
  std::vector<uint8_t> data;
  bool little = true;
  void u8(uint8_t v) { data.push_back(v); }
  void u16(uint16_t v) { little ? (u8(v & 0xff), u8(v >> 8)) : (u8(v >> 8), u8(v & 0xff)); }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) u8(static_cast<uint8_t>(v >> (8 * (little ? i : 3 - i))));
  }
  void text(const std::string& s) { data.insert(data.end(), s.begin(), s.end()); }
  void pad4() {
    while (data.size() % 4) u8(0);
  }
};

// A parameter list (PL_CDR_LE or _BE) with the participant's name, domain and, if `secure`, an
// identity token.
std::vector<uint8_t> parameters(const std::string& name, uint32_t domain, bool secure,
                                bool little) {
  Bytes p{{}, little};
  p.u8(0x00);
  p.u8(little ? 0x03 : 0x02);
  p.u16(0);
  p.u16(0x0015);  // PID_PROTOCOL_VERSION, 4 bytes: skipped
  p.u16(4);
  p.u32(0x02030000);
  p.u16(0x0062);  // PID_ENTITY_NAME
  const uint16_t length = static_cast<uint16_t>((4 + name.size() + 1 + 3) / 4 * 4);
  p.u16(length);
  p.u32(static_cast<uint32_t>(name.size() + 1));
  p.text(name);
  p.u8(0);
  p.pad4();
  p.u16(0x000f);  // PID_DOMAIN_ID
  p.u16(4);
  p.u32(domain);
  if (secure) {
    p.u16(0x1001);  // PID_IDENTITY_TOKEN: its content is not read
    p.u16(8);
    p.u32(0);
    p.u32(0);
  }
  p.u16(0x0001);  // PID_SENTINEL
  p.u16(0);
  return p.data;
}

// An RTPS message of INFO_TS then DATA from `writer` carrying `payload`.
std::vector<uint8_t> message(uint32_t writer, const std::vector<uint8_t>& payload,
                             bool little = true) {
  Bytes m{{}, little};
  m.text("RTPS");
  m.u8(2);
  m.u8(3);
  m.u8(0x01);  // vendor: eProsima
  m.u8(0x0f);
  for (uint8_t i = 1; i <= 12; ++i) m.u8(i);  // GUID prefix
  m.u8(0x09);                                 // INFO_TS
  m.u8(little ? 0x01 : 0x00);
  m.u16(8);
  m.u32(1);
  m.u32(2);
  m.u8(0x15);  // DATA, with serialized data
  m.u8(static_cast<uint8_t>((little ? 0x01 : 0x00) | 0x04));
  m.u16(static_cast<uint16_t>(20 + payload.size()));
  m.u16(0);   // extra flags
  m.u16(16);  // octets to inline QoS: after this field to the payload
  // The reader (SPDP's) and the writer: entity ids are octet arrays, big-endian in any message.
  for (uint32_t id : {0x000100c7u, writer}) {
    for (int i = 3; i >= 0; --i) m.u8(static_cast<uint8_t>(id >> (8 * i)));
  }
  m.u32(0);  // sequence number, high
  m.u32(1);  // and low
  m.data.insert(m.data.end(), payload.begin(), payload.end());
  return m.data;
}

TEST(ParticipantAnnouncements, ReadsANameDomainAndSecurityFromAnSpdpData) {
  const auto packet = message(0x000100c2, parameters("cam_0", 7, true, true));
  const auto participant = parse_participant_announcement(packet);
  ASSERT_TRUE(participant);
  EXPECT_EQ(participant->name, "cam_0");
  EXPECT_EQ(participant->domain, 7);
  EXPECT_TRUE(participant->secure);
  EXPECT_EQ(participant->vendor, "eProsima Fast DDS");
  EXPECT_EQ(participant->guid_prefix, "0102030405060708090a0b0c");
}

TEST(ParticipantAnnouncements, ReadsBigEndianSubmessagesAndParameters) {
  const auto packet = message(0x000100c2, parameters("compute", 42, false, false), false);
  const auto participant = parse_participant_announcement(packet);
  ASSERT_TRUE(participant);
  EXPECT_EQ(participant->name, "compute");
  EXPECT_EQ(participant->domain, 42);
  EXPECT_FALSE(participant->secure);
}

TEST(ParticipantAnnouncements, RefusesWhatIsNotAnAnnouncementAndNeverReadsPastTheEnd) {
  const auto packet = message(0x000100c2, parameters("cam_0", 7, false, true));
  // Another writer's DATA (an endpoint announcement): not a participant.
  EXPECT_FALSE(
      parse_participant_announcement(message(0x000003c2, parameters("x", 7, false, true))));
  EXPECT_FALSE(parse_participant_announcement(std::vector<uint8_t>{'R', 'T', 'P', 'X'}));
  // Every truncation of a valid one: nothing, or never a read past the end (AddressSanitizer).
  for (size_t size = 0; size < packet.size(); ++size) {
    const std::vector<uint8_t> cut(packet.begin(), packet.begin() + static_cast<ptrdiff_t>(size));
    EXPECT_FALSE(parse_participant_announcement(cut)) << size;
  }
}

// A participant of this build (Fast DDS or Cyclone DDS, as the tests run) heard on its domain's
// discovery port, with the name it was given.
TEST(ParticipantAnnouncements, HearsAParticipantOfThisBuildByName) {
  const int domain = test::test_domain(53);
  DdsOptions options;
  options.domain_id = domain;
  setenv("MOCAP_DOMAIN_ID", std::to_string(domain).c_str(), 1);
  auto transport = make_dds_transport(options, "announced_here");
  const auto heard = listen_for_participants({domain}, std::chrono::milliseconds(4000));
  unsetenv("MOCAP_DOMAIN_ID");
  bool found = false;
  for (const AnnouncedParticipant& participant : heard) {
    if (participant.name != "announced_here") continue;
    found = true;
    EXPECT_EQ(participant.domain, domain);
    EXPECT_FALSE(participant.secure);
  }
  EXPECT_TRUE(found) << heard.size() << " participant(s) heard";
}

}  // namespace
}  // namespace mocap
