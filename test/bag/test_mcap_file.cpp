// MCAP files (bag/src/mcap_*.hpp): what the writer writes, the reader reads back, byte for
// byte, with every compression; a writer that never closed (killed) leaves its flushed chunks
// readable; a file cut short or a chunk garbled is read around the damage and the damage said.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <mocap/bag/bag_error.hpp>

#include "mcap_format.hpp"
#include "mcap_reader.hpp"
#include "mcap_writer.hpp"
#include "test/test_support.hpp"

namespace mocap::bag::mcap {
namespace {

using ::testing::HasSubstr;

// Message i: its size and bytes follow from i, so a reader's result can be checked alone.
std::vector<uint8_t> payload(size_t i) {
  std::vector<uint8_t> bytes(4 + (i * 7919) % 3000);
  bytes[0] = 0;  // the CDR encapsulation header, as rosbag2 stores it
  bytes[1] = 1;
  for (size_t k = 4; k < bytes.size(); ++k)
    bytes[k] = static_cast<uint8_t>((i * 31 + k / 16) & 0xFF);
  return bytes;
}

struct Written {
  uint16_t images = 0, numbers = 0;
};

// `count` messages alternating between two channels, log times 1 ms apart.
Written write_messages(FileWriter& writer, size_t count, size_t from = 0) {
  Written ids;
  if (from == 0) {
    const uint16_t schema = writer.add_schema("std_msgs/msg/ByteMultiArray", "ros2idl", "idl text");
    ids.images = writer.add_channel("/camera/ir/image_raw", schema, "cdr",
                                    {{"offered_qos_profiles", "- history: 1\n"}});
    ids.numbers = writer.add_channel("/numbers", schema, "cdr", {});
  } else {
    ids = {1, 2};
  }
  for (size_t i = from; i < from + count; ++i) {
    const std::vector<uint8_t> data = payload(i);
    writer.write(i % 2 == 0 ? ids.images : ids.numbers, 1'000'000 * (i + 1), 1'000'000 * (i + 1),
                 data);
  }
  return ids;
}

// Every message the reader places, checked against payload(): returns their indices.
std::vector<size_t> read_back(FileReader& reader) {
  std::vector<size_t> indices;
  for (const MessagePlace& place : reader.messages()) {
    const size_t i = place.log_time / 1'000'000 - 1;
    const std::vector<uint8_t> expected = payload(i);
    const std::span<const uint8_t> data = reader.data(place);
    EXPECT_EQ(std::vector<uint8_t>(data.begin(), data.end()), expected) << "message " << i;
    EXPECT_EQ(reader.channels().at(place.channel_id).topic,
              i % 2 == 0 ? "/camera/ir/image_raw" : "/numbers");
    indices.push_back(i);
  }
  return indices;
}

std::vector<size_t> range(size_t from, size_t to) {
  std::vector<size_t> out;
  for (size_t i = from; i < to; ++i) out.push_back(i);
  return out;
}

TEST(McapFormat, Crc32IsZlibs) {
  EXPECT_EQ(crc32(std::string_view("123456789")), 0xCBF43926u);
  EXPECT_EQ(crc32(std::string_view("6789"), crc32(std::string_view("12345"))), 0xCBF43926u);
}

TEST(McapFile, EveryCompressionReadsBackWhatWasWritten) {
  for (const std::string compression : {"zstd", "lz4", ""}) {
    test::TempDir dir;
    const std::string path = (dir / "bag_0.mcap").string();
    FileWriter writer(path, {.chunk_size = 64 * 1024, .compression = compression});
    write_messages(writer, 2000);
    writer.close();

    FileReader reader(path);
    EXPECT_TRUE(reader.complete()) << compression;
    EXPECT_TRUE(reader.problems().empty()) << compression << ": " << reader.problems().front();
    EXPECT_EQ(reader.header().profile, "ros2");
    ASSERT_EQ(reader.channels().size(), 2u);
    EXPECT_EQ(reader.channels().at(1).metadata.at("offered_qos_profiles"), "- history: 1\n");
    EXPECT_EQ(reader.schemas().at(1).encoding, "ros2idl");
    EXPECT_EQ(read_back(reader), range(0, 2000)) << compression;
    if (!compression.empty()) {
      EXPECT_LT(writer.file_bytes(), 2000u * 1500 / 2) << compression << " did not compress";
    }
  }
}

TEST(McapFile, AWriterThatNeverClosedLeavesItsFlushedChunks) {
  test::TempDir dir;
  const std::string path = (dir / "bag_0.mcap").string();
  {
    FileWriter writer(path, {.chunk_size = 1 << 20});
    write_messages(writer, 300);
    writer.flush();
    write_messages(writer, 200, 300);  // in the open chunk when the writer dies
  }  // destroyed without close(), as a SIGKILL would leave it (the open chunk never written)
  FileReader reader(path);
  EXPECT_FALSE(reader.complete());
  EXPECT_TRUE(reader.problems().empty()) << reader.problems().front();
  EXPECT_EQ(read_back(reader), range(0, 300));
}

TEST(McapFile, AFileCutShortIsReadToTheCut) {
  test::TempDir dir;
  const std::string path = (dir / "bag_0.mcap").string();
  FileWriter writer(path, {.chunk_size = 32 * 1024});
  write_messages(writer, 1000);
  writer.close();
  const uintmax_t size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size * 2 / 3);

  FileReader reader(path);
  EXPECT_FALSE(reader.complete());
  ASSERT_EQ(reader.problems().size(), 1u);
  EXPECT_THAT(reader.problems()[0], HasSubstr("cut short"));
  const std::vector<size_t> read = read_back(reader);
  ASSERT_FALSE(read.empty());
  EXPECT_EQ(read, range(0, read.size())) << "the messages before the cut, all of them";
  EXPECT_GT(read.size(), 500u);
}

TEST(McapFile, AGarbledChunkIsSkippedAndSaidAndTheOthersRead) {
  test::TempDir dir;
  const std::string path = (dir / "bag_0.mcap").string();
  FileWriter writer(path, {.chunk_size = 32 * 1024, .compression = "zstd"});
  write_messages(writer, 1000);
  writer.close();
  FileReader intact(path);
  ASSERT_GT(intact.messages().size(), 0u);
  // The middle message's chunk: garble bytes in its compressed records.
  const MessagePlace middle = intact.messages()[500];
  std::vector<size_t> in_chunk;
  for (const MessagePlace& place : intact.messages()) {
    if (place.chunk == middle.chunk) in_chunk.push_back(place.log_time / 1'000'000 - 1);
  }
  std::string bytes = test::read_file(path);
  // Chunk records begin after the magic and the Header; find the chunk by scanning records.
  size_t offset = kMagic.size(), chunk = 0, garbled_at = 0;
  while (auto record = next_record(bytes, offset)) {
    if (record->opcode == static_cast<uint8_t>(Op::kChunk) && chunk++ == middle.chunk) {
      garbled_at =
          static_cast<size_t>(record->content.data() - bytes.data()) + record->content.size() / 2;
      break;
    }
  }
  ASSERT_GT(garbled_at, 0u);
  for (size_t i = 0; i < 64; ++i)
    bytes[garbled_at + i] = static_cast<char>(bytes[garbled_at + i] ^ 0x5A);
  test::write_file(path, bytes);

  FileReader reader(path);
  EXPECT_TRUE(reader.complete());
  ASSERT_EQ(reader.problems().size(), 1u);
  EXPECT_THAT(reader.problems()[0], HasSubstr("a chunk unreadable"));
  std::vector<size_t> expected;
  for (size_t i = 0; i < 1000; ++i) {
    if (std::find(in_chunk.begin(), in_chunk.end(), i) == in_chunk.end()) expected.push_back(i);
  }
  EXPECT_EQ(read_back(reader), expected);
}

TEST(McapFile, NotMcapIsRefusedWithTheFileNamed) {
  test::TempDir dir;
  test::write_file(dir / "x.mcap", "SQLite format 3");
  try {
    FileReader reader((dir / "x.mcap").string());
    FAIL() << "read as MCAP";
  } catch (const BagError& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.mcap: not an MCAP file"));
  }
}

}  // namespace
}  // namespace mocap::bag::mcap
