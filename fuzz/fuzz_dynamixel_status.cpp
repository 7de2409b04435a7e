// Dynamixel Protocol 1.0 from the servo bus, where noise and collisions happen: the parser
// counts bad headers and checksums and never throws, holds at most one packet's bytes, and how
// the bytes are split into reads changes nothing. What it yields re-encodes (encode_status) to
// bytes that parse to the same packet.
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string_view>
#include <vector>

#include "follower/dynamixel/protocol.hpp"

namespace {

bool same_stats(const mocap::dynamixel::PacketParserStats& a,
                const mocap::dynamixel::PacketParserStats& b) {
  return a.packets == b.packets && a.checksum_errors == b.checksum_errors &&
         a.length_errors == b.length_errors && a.discarded_bytes == b.discarded_bytes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using mocap::dynamixel::Packet;
  using mocap::dynamixel::PacketParser;
  if (size < 1) return 0;
  // The first byte: bit 0 asks for bad checksums (as the simulated servos do), the rest is the
  // size of the reads. Then the bytes on the bus.
  const mocap::dynamixel::PacketParserOptions options{.deliver_bad_checksums = (data[0] & 1) != 0};
  const size_t read_size = 1 + (data[0] >> 1);
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  // FF FF ID LEN and LEN bytes: the most an unfinished packet can hold.
  const size_t max_pending = 4 + options.max_length;

  PacketParser reads(options);
  std::vector<Packet> packets;
  for (size_t offset = 0; offset < bytes.size(); offset += read_size) {
    reads.feed(bytes.substr(offset, read_size));
    if (reads.pending_bytes() > max_pending) std::abort();
    while (std::optional<Packet> packet = reads.next()) packets.push_back(std::move(*packet));
  }
  PacketParser at_once(options);
  at_once.feed(bytes);
  if (at_once.take_packets() != packets || !same_stats(at_once.stats(), reads.stats())) {
    std::abort();
  }

  for (const Packet& packet : packets) {
    if (!packet.checksum_ok && !options.deliver_bad_checksums) std::abort();
    PacketParser again(options);
    again.feed(mocap::dynamixel::encode_status(packet.id, packet.code, packet.parameters));
    Packet expected = packet;
    expected.checksum_ok = true;
    const std::vector<Packet> back = again.take_packets();
    if (back.size() != 1 || back[0] != expected || again.pending_bytes() != 0) std::abort();
  }
  return 0;
}
