// Dynamixel Protocol 1.0, the half-duplex serial protocol of the AX, RX, EX and MX servos
// (ROBOTIS' Protocol 1.0 manual). The host sends instruction packets, the addressed servo
// answers with a status packet:
//
//   instruction  FF FF ID LEN INSTRUCTION PARAM... CHK
//   status       FF FF ID LEN ERROR PARAM... CHK
//
// LEN counts the parameters plus 2 (the instruction or error byte and the checksum), and
// CHK = ~(ID + LEN + INSTRUCTION/ERROR + PARAM...) & 0xFF. A packet to the broadcast ID 0xFE
// reaches every servo and is never answered. Multi-byte values are little-endian.
//
// One packet layout serves both directions, so one parser reads the servos' status packets
// (the driver) and the host's instruction packets (the simulated servos).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::dynamixel {

// The ID every servo obeys and none answers.
constexpr uint8_t kBroadcastId = 0xFE;
// Servo IDs are 0..kMaxServoId (0xFF would be taken for a header byte).
constexpr uint8_t kMaxServoId = 0xFD;
// LEN is one byte, and counts the instruction or error byte and the checksum too.
constexpr size_t kMaxParameters = 253;

enum class Instruction : uint8_t {
  kPing = 0x01,       // no parameters; the servo answers with an empty status
  kRead = 0x02,       // address, length; answered with that many bytes of the control table
  kWrite = 0x03,      // address, data...
  kRegWrite = 0x04,   // as kWrite, but held until kAction
  kAction = 0x05,     // executes every held kRegWrite (usually broadcast)
  kReset = 0x06,      // factory defaults, ID 1 included
  kSyncWrite = 0x83,  // broadcast: address, length, then (id, data...) per servo; no answer
};

// "PING", "READ", ..., "SYNC_WRITE"; "instruction 0x42" for a code that is none of them.
std::string instruction_name(uint8_t instruction);

// The bits of a status packet's error byte: what the servo found wrong with the instruction
// (angle limit, range, checksum, instruction) or with itself (voltage, heat, load).
namespace error_bit {
constexpr uint8_t kInputVoltage = 1 << 0;  // supply outside the voltage limits
constexpr uint8_t kAngleLimit = 1 << 1;    // goal position outside the angle limits
constexpr uint8_t kOverheating = 1 << 2;   // temperature above the temperature limit
constexpr uint8_t kRange = 1 << 3;         // a value, address or length out of range
constexpr uint8_t kChecksum = 1 << 4;      // the instruction packet's checksum was wrong
constexpr uint8_t kOverload = 1 << 5;      // the load exceeded the torque limit
constexpr uint8_t kInstruction = 1 << 6;   // unknown instruction, or ACTION without REG_WRITE
}  // namespace error_bit

// The names of the set bits, lowest first, comma-separated: "overheating, overload"; "none"
// for 0. Bit 7, which no servo sets, is "bit 7".
std::string describe_errors(uint8_t errors);

// ~(sum of `body`) & 0xFF, where `body` is a packet without its FF FF header and checksum:
// ID, LEN, instruction or error, parameters.
uint8_t checksum(std::span<const uint8_t> body);

// One packet, either direction. For an instruction packet `code` is the instruction, for a
// status packet the error byte.
struct Packet {
  uint8_t id = 0;
  uint8_t code = 0;
  std::vector<uint8_t> parameters;
  // False only for packets a parser with deliver_bad_checksums passed on despite their
  // checksum.
  bool checksum_ok = true;

  bool operator==(const Packet&) const = default;
};

// --- Encoders: the packet's bytes, header and checksum included ----------------------------
// All throw std::invalid_argument for more than kMaxParameters parameters.

std::string encode_packet(uint8_t id, uint8_t code, std::span<const uint8_t> parameters);
std::string encode_ping(uint8_t id);
std::string encode_read(uint8_t id, uint8_t address, uint8_t length);
std::string encode_write(uint8_t id, uint8_t address, std::span<const uint8_t> data);
std::string encode_reg_write(uint8_t id, uint8_t address, std::span<const uint8_t> data);
std::string encode_action(uint8_t id = kBroadcastId);
std::string encode_reset(uint8_t id);

// One servo's share of a SYNC_WRITE.
struct SyncWriteItem {
  uint8_t id = 0;
  std::vector<uint8_t> data;  // data_length bytes for the control table from the start address
};
// A SYNC_WRITE to the broadcast ID: `data_length` bytes from `address` on every listed
// servo. Throws std::invalid_argument when an item's data is not data_length bytes long, an
// ID is the broadcast ID, or the packet would be too long.
std::string encode_sync_write(uint8_t address, uint8_t data_length,
                              std::span<const SyncWriteItem> items);

// A status packet: the servo's `errors` byte and the bytes it answers with.
std::string encode_status(uint8_t id, uint8_t errors, std::span<const uint8_t> parameters = {});

// --- Parser --------------------------------------------------------------------------------

struct PacketParserOptions {
  // Packets whose checksum is wrong are counted and dropped, and the parser looks for the next
  // header from the byte after the bad packet's header (its LEN may have been the corrupted
  // byte). A servo must answer such an instruction with error_bit::kChecksum, so the
  // simulated servos ask for them: the packet is yielded with checksum_ok false instead.
  bool deliver_bad_checksums = false;
  // LEN above this is a length error: the header is dropped and the search goes on. LEN below
  // 2 always is one.
  size_t max_length = kMaxParameters + 2;

  // Why these options cannot be used, naming the field ("max_length: 1; a packet's LEN is 2 at
  // least"); nullopt when they can. PacketParser's constructor throws std::invalid_argument
  // with it.
  std::optional<std::string> problem() const;
};

struct PacketParserStats {
  uint64_t packets = 0;          // yielded, bad-checksum ones delivered on request included
  uint64_t checksum_errors = 0;  // packets whose checksum was wrong
  uint64_t length_errors = 0;    // headers with an impossible LEN
  uint64_t discarded_bytes = 0;  // bytes outside packets: garbage, headers of rejected packets
};

// Finds packets in a byte stream that arrives in chunks of any size: a packet split across
// reads is completed by the next feed, garbage before and between packets is skipped (the
// parser resynchronises on the next FF FF; a run of more than two FF bytes is a header with
// extra fill bytes), bad checksums and impossible lengths are counted, never thrown. Not
// thread-safe.
class PacketParser {
 public:
  explicit PacketParser(PacketParserOptions options = {});

  // Parses `bytes`; the packets they complete wait in next().
  void feed(std::string_view bytes);
  // The oldest packet completed and not yet taken, or nullopt.
  std::optional<Packet> next();
  // Every packet completed and not yet taken, oldest first.
  std::vector<Packet> take_packets();

  // Bytes of an unfinished packet (or of a header candidate) waiting for the rest.
  size_t pending_bytes() const { return buffer_.size(); }
  // Forgets unfinished and untaken packets, e.g. before the next transaction. Keeps the counts.
  void reset();

  const PacketParserStats& stats() const { return stats_; }

 private:
  void parse();
  void discard(size_t count);

  PacketParserOptions options_;
  std::string buffer_;  // unparsed bytes, starting at a header candidate once parse() is done
  std::vector<Packet> packets_;
  size_t next_packet_ = 0;
  PacketParserStats stats_;
};

}  // namespace mocap::dynamixel
