// Dynamixel Protocol 1.0 packets: the byte examples of ROBOTIS' Protocol 1.0 and AX/DX
// manuals (checksums recomputed here, not copied), error bits, the streaming parser, and the
// AX-12A control table and unit conversions.
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "follower/dynamixel/ax12_control_table.hpp"
#include "follower/dynamixel/protocol.hpp"

namespace mocap::dynamixel {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string bytes(std::initializer_list<int> values) {
  std::string out;
  for (int value : values) out += static_cast<char>(value);
  return out;
}

std::string hex(const std::string& data) {
  std::string out;
  for (char c : data) {
    out += fmt::format("{}{:02X}", out.empty() ? "" : " ", static_cast<uint8_t>(c));
  }
  return out;
}

// The checksum computed from the definition, independently of protocol.cpp.
int expected_checksum(std::initializer_list<int> body) {
  int sum = 0;
  for (int value : body) sum += value;
  return ~sum & 0xFF;
}

std::vector<Packet> parse_all(const std::string& data, PacketParser& parser) {
  parser.feed(data);
  return parser.take_packets();
}

// --- The manuals' examples -----------------------------------------------------------------

TEST(DynamixelProtocol, PingOfId1AndItsAnswer) {
  EXPECT_EQ(expected_checksum({0x01, 0x02, 0x01}), 0xFB);
  EXPECT_EQ(hex(encode_ping(1)), hex(bytes({0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB})));
  const std::string answer = bytes({0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC});
  EXPECT_EQ(hex(encode_status(1, 0)), hex(answer));
  PacketParser parser;
  const std::vector<Packet> packets = parse_all(answer, parser);
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0], (Packet{.id = 1, .code = 0, .parameters = {}}));
}

TEST(DynamixelProtocol, ReadOfTheInternalTemperatureOfId1) {
  EXPECT_EQ(ax12::kPresentTemperature, 0x2B);
  EXPECT_EQ(expected_checksum({0x01, 0x04, 0x02, 0x2B, 0x01}), 0xCC);
  EXPECT_EQ(hex(encode_read(1, ax12::kPresentTemperature, 1)),
            hex(bytes({0xFF, 0xFF, 0x01, 0x04, 0x02, 0x2B, 0x01, 0xCC})));
  // The answer: 0x20, 32 degrees Celsius.
  const std::string answer = bytes({0xFF, 0xFF, 0x01, 0x03, 0x00, 0x20, 0xDB});
  EXPECT_EQ(expected_checksum({0x01, 0x03, 0x00, 0x20}), 0xDB);
  const std::vector<uint8_t> data{0x20};
  EXPECT_EQ(hex(encode_status(1, 0, data)), hex(answer));
  PacketParser parser;
  const std::vector<Packet> packets = parse_all(answer, parser);
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].id, 1);
  EXPECT_EQ(packets[0].code, 0);
  ASSERT_EQ(packets[0].parameters.size(), 1u);
  EXPECT_EQ(ax12::temperature_to_celsius(packets[0].parameters[0]), 32.0);
}

TEST(DynamixelProtocol, WritesOfTheIdAndOfThePunch) {
  // ID 1 -> ID 0: the checksum is ~(01 + 04 + 03 + 03 + 00) = ~0x0B = 0xF4.
  EXPECT_EQ(expected_checksum({0x01, 0x04, 0x03, 0x03, 0x00}), 0xF4);
  const std::vector<uint8_t> zero{0};
  EXPECT_EQ(hex(encode_write(1, ax12::kId, zero)),
            hex(bytes({0xFF, 0xFF, 0x01, 0x04, 0x03, 0x03, 0x00, 0xF4})));
  // Any connected servo -> ID 1, by broadcast; the sum 0x109 overflows a byte.
  const std::vector<uint8_t> one{1};
  EXPECT_EQ(hex(encode_write(kBroadcastId, ax12::kId, one)),
            hex(bytes({0xFF, 0xFF, 0xFE, 0x04, 0x03, 0x03, 0x01, 0xF6})));
  // Punch of ID 0 to 0x40, a two-byte register, low byte first.
  const auto punch = ax12::u16_bytes(0x40);
  EXPECT_EQ(hex(encode_write(0, ax12::kPunch, punch)),
            hex(bytes({0xFF, 0xFF, 0x00, 0x05, 0x03, 0x30, 0x40, 0x00, 0x87})));
  // The same write to a locked servo is refused with the range error.
  PacketParser parser;
  const std::vector<Packet> packets =
      parse_all(bytes({0xFF, 0xFF, 0x00, 0x02, 0x08, 0xF5}), parser);
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].code, error_bit::kRange);
  EXPECT_EQ(describe_errors(packets[0].code), "range");
}

TEST(DynamixelProtocol, ResetAndAction) {
  EXPECT_EQ(hex(encode_reset(0)), hex(bytes({0xFF, 0xFF, 0x00, 0x02, 0x06, 0xF7})));
  EXPECT_EQ(hex(encode_status(0, 0)), hex(bytes({0xFF, 0xFF, 0x00, 0x02, 0x00, 0xFD})));
  EXPECT_EQ(hex(encode_action()), hex(bytes({0xFF, 0xFF, 0xFE, 0x02, 0x05, 0xFA})));
  const std::vector<uint8_t> goal{0x00, 0x02};
  EXPECT_EQ(hex(encode_reg_write(3, ax12::kGoalPosition, goal)),
            hex(bytes({0xFF, 0xFF, 0x03, 0x05, 0x04, 0x1E, 0x00, 0x02,
                       expected_checksum({0x03, 0x05, 0x04, 0x1E, 0x00, 0x02})})));
}

TEST(DynamixelProtocol, SyncWriteOfGoalPositionAndSpeedToFourServos) {
  // IDs 0..3: position 0x010, 0x220, 0x030, 0x220; speed 0x150, 0x360, 0x170, 0x380.
  const std::vector<SyncWriteItem> items{{0, {0x10, 0x00, 0x50, 0x01}},
                                         {1, {0x20, 0x02, 0x60, 0x03}},
                                         {2, {0x30, 0x00, 0x70, 0x01}},
                                         {3, {0x20, 0x02, 0x80, 0x03}}};
  EXPECT_EQ(expected_checksum({0xFE, 0x18, 0x83, 0x1E, 0x04, 0x00, 0x10, 0x00, 0x50,
                               0x01, 0x01, 0x20, 0x02, 0x60, 0x03, 0x02, 0x30, 0x00,
                               0x70, 0x01, 0x03, 0x20, 0x02, 0x80, 0x03}),
            0x12);
  EXPECT_EQ(hex(encode_sync_write(ax12::kGoalPosition, 4, items)),
            hex(bytes({0xFF, 0xFF, 0xFE, 0x18, 0x83, 0x1E, 0x04, 0x00, 0x10, 0x00,
                       0x50, 0x01, 0x01, 0x20, 0x02, 0x60, 0x03, 0x02, 0x30, 0x00,
                       0x70, 0x01, 0x03, 0x20, 0x02, 0x80, 0x03, 0x12})));
  // Items must all be data_length long.
  const std::vector<SyncWriteItem> uneven{{0, {1, 2, 3, 4}}, {1, {1, 2}}};
  EXPECT_THROW(encode_sync_write(ax12::kGoalPosition, 4, uneven), std::invalid_argument);
}

TEST(DynamixelProtocol, TooManyParametersAreRefused) {
  EXPECT_NO_THROW(encode_packet(1, 0x03, std::vector<uint8_t>(kMaxParameters, 0)));
  EXPECT_THROW(encode_packet(1, 0x03, std::vector<uint8_t>(kMaxParameters + 1, 0)),
               std::invalid_argument);
}

TEST(DynamixelProtocol, InstructionNames) {
  EXPECT_EQ(instruction_name(0x01), "PING");
  EXPECT_EQ(instruction_name(0x02), "READ");
  EXPECT_EQ(instruction_name(0x03), "WRITE");
  EXPECT_EQ(instruction_name(0x04), "REG_WRITE");
  EXPECT_EQ(instruction_name(0x05), "ACTION");
  EXPECT_EQ(instruction_name(0x06), "RESET");
  EXPECT_EQ(instruction_name(0x83), "SYNC_WRITE");
  EXPECT_EQ(instruction_name(0x42), "instruction 0x42");
}

// --- Error bits ----------------------------------------------------------------------------

TEST(DynamixelProtocol, EveryErrorBitIsDecodedAndNamed) {
  const std::vector<std::pair<uint8_t, std::string>> bits{
      {error_bit::kInputVoltage, "input voltage"}, {error_bit::kAngleLimit, "angle limit"},
      {error_bit::kOverheating, "overheating"},    {error_bit::kRange, "range"},
      {error_bit::kChecksum, "checksum"},          {error_bit::kOverload, "overload"},
      {error_bit::kInstruction, "instruction"}};
  for (size_t bit = 0; bit < bits.size(); ++bit) {
    EXPECT_EQ(bits[bit].first, 1 << bit);
    EXPECT_EQ(describe_errors(bits[bit].first), bits[bit].second);
    // Through a status packet: the error byte survives encoding and parsing.
    PacketParser parser;
    parser.feed(encode_status(7, bits[bit].first));
    const std::optional<Packet> packet = parser.next();
    ASSERT_TRUE(packet.has_value());
    EXPECT_EQ(packet->code, bits[bit].first);
  }
  EXPECT_EQ(describe_errors(0), "none");
  EXPECT_EQ(describe_errors(error_bit::kOverheating | error_bit::kOverload),
            "overheating, overload");
  EXPECT_EQ(describe_errors(0x7F),
            "input voltage, angle limit, overheating, range, checksum, overload, instruction");
  EXPECT_EQ(describe_errors(0x80), "bit 7");
}

// --- Parser --------------------------------------------------------------------------------

TEST(DynamixelParser, PacketsSplitByteByByte) {
  const std::vector<uint8_t> data{0x34, 0x12};
  const std::string stream = encode_status(1, 0, data) + encode_ping(2) +
                             encode_status(3, error_bit::kOverload) + encode_read(4, 36, 2);
  PacketParser parser;
  std::vector<Packet> packets;
  for (char c : stream) {
    parser.feed(std::string_view(&c, 1));
    while (auto packet = parser.next()) packets.push_back(*packet);
  }
  ASSERT_EQ(packets.size(), 4u);
  EXPECT_EQ(packets[0], (Packet{.id = 1, .code = 0, .parameters = {0x34, 0x12}}));
  EXPECT_EQ(packets[1], (Packet{.id = 2, .code = 0x01, .parameters = {}}));
  EXPECT_EQ(packets[2], (Packet{.id = 3, .code = error_bit::kOverload, .parameters = {}}));
  EXPECT_EQ(packets[3], (Packet{.id = 4, .code = 0x02, .parameters = {36, 2}}));
  EXPECT_EQ(parser.stats().packets, 4u);
  EXPECT_EQ(parser.stats().checksum_errors, 0u);
  EXPECT_EQ(parser.stats().discarded_bytes, 0u);
  EXPECT_EQ(parser.pending_bytes(), 0u);
}

TEST(DynamixelParser, SkipsGarbageBeforeAndBetweenPackets) {
  // Garbage with lone FF bytes, a header with a third FF, and zeros between packets.
  const std::string garbage = bytes({0x00, 0x12, 0xFF, 0x7E, 0xFF});
  const std::string stream =
      garbage + encode_ping(1) + bytes({0x00, 0x00, 0x00}) + bytes({0xFF}) + encode_status(2, 0);
  PacketParser parser;
  // In chunks of three, so that headers are split too.
  std::vector<Packet> packets;
  for (size_t i = 0; i < stream.size(); i += 3) {
    parser.feed(std::string_view(stream).substr(i, 3));
    for (Packet& p : parser.take_packets()) packets.push_back(p);
  }
  ASSERT_EQ(packets.size(), 2u);
  EXPECT_EQ(packets[0].id, 1);
  EXPECT_EQ(packets[0].code, 0x01);
  EXPECT_EQ(packets[1].id, 2);
  EXPECT_EQ(packets[1].code, 0);
  EXPECT_EQ(parser.stats().checksum_errors, 0u);
  EXPECT_EQ(parser.stats().discarded_bytes, garbage.size() + 3 + 1);
}

TEST(DynamixelParser, BadChecksumsAreCountedAndDropped) {
  std::string bad = encode_status(1, 0, std::vector<uint8_t>{0x20});
  bad.back() = static_cast<char>(bad.back() ^ 0x01);
  PacketParser parser;
  const std::vector<Packet> packets = parse_all(bad + encode_status(2, 0) + bad, parser);
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].id, 2);
  EXPECT_EQ(parser.stats().checksum_errors, 2u);
  EXPECT_EQ(parser.stats().packets, 1u);
}

TEST(DynamixelParser, DeliversBadChecksumsWhenAsked) {
  std::string bad = encode_read(1, 43, 1);
  bad.back() = static_cast<char>(bad.back() + 1);
  PacketParser parser(PacketParserOptions{.deliver_bad_checksums = true});
  const std::vector<Packet> packets = parse_all(bad + encode_ping(1), parser);
  ASSERT_EQ(packets.size(), 2u);
  EXPECT_FALSE(packets[0].checksum_ok);
  EXPECT_EQ(packets[0].code, 0x02);
  EXPECT_EQ(packets[0].parameters, (std::vector<uint8_t>{43, 1}));
  EXPECT_TRUE(packets[1].checksum_ok);
  EXPECT_EQ(parser.stats().checksum_errors, 1u);
}

TEST(DynamixelParser, ImpossibleLengthsAreCounted) {
  // LEN 1 and LEN 0 cannot be: the header is dropped and the search goes on.
  const std::string stream =
      bytes({0xFF, 0xFF, 0x01, 0x01, 0xFD}) + bytes({0xFF, 0xFF, 0x01, 0x00}) + encode_ping(5);
  PacketParser parser;
  const std::vector<Packet> packets = parse_all(stream, parser);
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].id, 5);
  EXPECT_EQ(parser.stats().length_errors, 2u);
  // A smaller maximum length rejects longer packets.
  PacketParser short_packets(PacketParserOptions{.max_length = 3});
  const std::vector<Packet> none =
      parse_all(encode_status(1, 0, std::vector<uint8_t>{1, 2}) + encode_ping(6), short_packets);
  ASSERT_EQ(none.size(), 1u);
  EXPECT_EQ(none[0].id, 6);
  EXPECT_EQ(short_packets.stats().length_errors, 1u);
}

TEST(DynamixelParser, TruncatedPackets) {
  const std::string whole = encode_status(1, 0, std::vector<uint8_t>{0x20});
  const std::string truncated = whole.substr(0, whole.size() - 2);
  // Alone: nothing yet, the bytes wait for the rest.
  PacketParser parser;
  EXPECT_TRUE(parse_all(truncated, parser).empty());
  EXPECT_EQ(parser.pending_bytes(), truncated.size());
  // reset() forgets it: the next packet parses on its own.
  parser.reset();
  EXPECT_EQ(parser.pending_bytes(), 0u);
  std::vector<Packet> packets = parse_all(encode_ping(3), parser);
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0].id, 3);

  // Followed by a whole packet: the cut one takes the next bytes, fails its checksum, and the
  // search resumes inside it, finding the whole packet.
  PacketParser resync;
  packets = parse_all(truncated + whole, resync);
  ASSERT_EQ(packets.size(), 1u);
  EXPECT_EQ(packets[0], (Packet{.id = 1, .code = 0, .parameters = {0x20}}));
  EXPECT_EQ(resync.stats().checksum_errors, 1u);
  EXPECT_EQ(resync.pending_bytes(), 0u);
}

// --- AX-12A control table ------------------------------------------------------------------

TEST(Ax12ControlTable, AddressesWidthsAndDefaults) {
  struct Expected {
    uint8_t address;
    uint8_t width;
    bool read_only;
    uint16_t default_value;
  };
  const std::vector<Expected> expected{
      {0, 2, true, 12},   {2, 1, true, 24},    {3, 1, false, 1},     {4, 1, false, 1},
      {5, 1, false, 250}, {6, 2, false, 0},    {8, 2, false, 1023},  {11, 1, false, 70},
      {12, 1, false, 60}, {13, 1, false, 140}, {14, 2, false, 1023}, {16, 1, false, 2},
      {17, 1, false, 36}, {18, 1, false, 36},  {24, 1, false, 0},    {25, 1, false, 0},
      {30, 2, false, 0},  {32, 2, false, 0},   {34, 2, false, 1023}, {36, 2, true, 0},
      {38, 2, true, 0},   {40, 2, true, 0},    {42, 1, true, 0},     {43, 1, true, 0},
      {44, 1, true, 0},   {46, 1, true, 0},    {47, 1, false, 0},    {48, 2, false, 32}};
  for (const Expected& e : expected) {
    const ax12::Register* reg = ax12::find_register(e.address);
    ASSERT_NE(reg, nullptr) << int{e.address};
    EXPECT_EQ(reg->width, e.width) << reg->name;
    EXPECT_EQ(reg->read_only, e.read_only) << reg->name;
    EXPECT_EQ(reg->default_value, e.default_value) << reg->name;
    EXPECT_EQ(reg->eeprom(), e.address < 24) << reg->name;
  }
  // The second byte of a two-byte register belongs to it; gaps belong to none.
  EXPECT_EQ(ax12::find_register(31), nullptr);
  EXPECT_EQ(ax12::register_at(31)->address, ax12::kGoalPosition);
  EXPECT_EQ(ax12::register_at(10), nullptr);
  EXPECT_EQ(ax12::register_at(45), nullptr);
  EXPECT_EQ(ax12::register_at(50), nullptr);

  const auto table = ax12::default_control_table(7);
  EXPECT_EQ(table[ax12::kId], 7);
  EXPECT_EQ(ax12::get_u16(table, ax12::kModelNumber), 12);
  EXPECT_EQ(ax12::get_u16(table, ax12::kCcwAngleLimit), 1023);
  EXPECT_EQ(table[ax12::kCcwAngleLimit], 0xFF);  // little-endian
  EXPECT_EQ(table[ax12::kCcwAngleLimit + 1], 0x03);
  EXPECT_EQ(table[ax12::kTemperatureLimit], 70);
  EXPECT_EQ(table[ax12::kAlarmShutdown], error_bit::kOverheating | error_bit::kOverload);
}

TEST(Ax12ControlTable, PositionConversions) {
  EXPECT_EQ(ax12::position_to_radians(512), 0.0);
  EXPECT_NEAR(ax12::position_to_radians(0), -150 * kPi / 180, 1e-12);
  EXPECT_NEAR(ax12::position_to_radians(1023), (150 - 300.0 / 1024) * kPi / 180, 1e-12);
  EXPECT_NEAR(ax12::position_to_radians(5000), ax12::position_to_radians(1023), 1e-12);
  EXPECT_EQ(ax12::radians_to_position(0), 512);
  EXPECT_EQ(ax12::radians_to_position(kPi / 2), 512 + 307);  // 90 degrees: 307.2 units
  EXPECT_EQ(ax12::radians_to_position(-kPi / 2), 512 - 307);
  EXPECT_EQ(ax12::radians_to_position(10), 1023);  // clamped
  EXPECT_EQ(ax12::radians_to_position(-10), 0);
  EXPECT_EQ(ax12::radians_to_position(std::nan("")), 0);
  for (uint16_t units : {0, 1, 100, 511, 512, 513, 900, 1023}) {
    EXPECT_EQ(ax12::radians_to_position(ax12::position_to_radians(units)), units);
  }
}

TEST(Ax12ControlTable, SpeedLoadVoltageAndTemperatureConversions) {
  const double rad_s_per_unit = 0.111 * 2 * kPi / 60;
  EXPECT_NEAR(ax12::moving_speed_to_rad_s(100), 100 * rad_s_per_unit, 1e-12);
  EXPECT_NEAR(ax12::moving_speed_to_rad_s(0), 114 * 2 * kPi / 60, 1e-12);  // no control
  EXPECT_NEAR(ax12::moving_speed_to_rad_s(2000), 1023 * rad_s_per_unit, 1e-12);
  EXPECT_EQ(ax12::rad_s_to_moving_speed(100 * rad_s_per_unit), 100);
  EXPECT_EQ(ax12::rad_s_to_moving_speed(-100 * rad_s_per_unit), 100);
  EXPECT_EQ(ax12::rad_s_to_moving_speed(0), 1);  // never "as fast as possible"
  EXPECT_EQ(ax12::rad_s_to_moving_speed(100), 1023);

  EXPECT_EQ(ax12::from_direction_bit(300), 300);
  EXPECT_EQ(ax12::from_direction_bit(1024 + 300), -300);
  EXPECT_EQ(ax12::to_direction_bit(-300), 1024 + 300);
  EXPECT_EQ(ax12::to_direction_bit(300), 300);
  EXPECT_EQ(ax12::to_direction_bit(-5000), 1024 + 1023);
  EXPECT_NEAR(ax12::present_speed_to_rad_s(1024 + 100), -100 * rad_s_per_unit, 1e-12);
  EXPECT_NEAR(ax12::present_load_to_fraction(1023), 1.0, 1e-12);
  EXPECT_NEAR(ax12::present_load_to_fraction(1024 + 512), -512 / 1023.0, 1e-12);
  EXPECT_NEAR(ax12::voltage_to_volts(121), 12.1, 1e-12);
  EXPECT_EQ(ax12::temperature_to_celsius(70), 70.0);
}

// Below 2 every LEN would be a length error: the parser would find no packet at all.
TEST(PacketParserOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(PacketParserOptions{}.problem(), std::nullopt);
  EXPECT_EQ(PacketParserOptions{.max_length = 2}.problem(), std::nullopt);
  EXPECT_EQ(PacketParserOptions{.max_length = 1}.problem(),
            "max_length: 1; a packet's LEN is 2 at least");
  try {
    PacketParser parser({.max_length = 0});
    ADD_FAILURE() << "max_length 0 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "PacketParserOptions::max_length: 0; a packet's LEN is 2 at least");
  }
}

}  // namespace
}  // namespace mocap::dynamixel
