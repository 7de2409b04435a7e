// MCAP's binary layout (https://mcap.dev/spec, written here from the specification): the
// records a bag writes and reads, their little-endian encoding, and CRC-32. No I/O here: the
// writer and reader own their files.
//
//   <magic> <Header> <data records...> <DataEnd> <summary records...> <SummaryOffsets> <Footer>
//   <magic>
//
// Every record is `opcode:u8 | length:u64 | content`. Readers skip opcodes they do not know
// and bytes past the fields they know (records may grow fields at their end).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mocap::bag::mcap {

inline constexpr std::string_view kMagic{"\x89MCAP0\r\n", 8};
// Opcode, then the content's length.
inline constexpr size_t kRecordPrefix = 1 + 8;

enum class Op : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// CRC-32 as zlib and MCAP compute it (reflected 0xEDB88320, initial and final XOR 0xFFFFFFFF).
// `crc` continues an earlier one: crc32(b, crc32(a)) == crc32(a + b).
uint32_t crc32(std::span<const uint8_t> bytes, uint32_t crc = 0);
uint32_t crc32(std::string_view bytes, uint32_t crc = 0);

// Records as fields. Strings are bytes (MCAP says UTF-8; a topic name may be anything).
struct Header {
  std::string profile, library;
};
struct Schema {
  uint16_t id = 0;
  std::string name, encoding, data;
};
struct Channel {
  uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
  std::map<std::string, std::string> metadata;
};
struct MessageHeader {  // a Message's fields before its data
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0, publish_time = 0;
};
inline constexpr size_t kMessageHeaderSize = 2 + 4 + 8 + 8;
struct Chunk {
  uint64_t message_start_time = 0, message_end_time = 0, uncompressed_size = 0;
  uint32_t uncompressed_crc = 0;  // 0: not computed
  std::string compression;        // "", "zstd" or "lz4"
  std::string_view records;       // compressed as `compression` says; points into the input
};
struct MessageIndex {
  uint16_t channel_id = 0;
  std::vector<std::pair<uint64_t, uint64_t>> entries;  // (log_time, offset in the chunk)
};
struct ChunkIndex {
  uint64_t message_start_time = 0, message_end_time = 0, chunk_start_offset = 0, chunk_length = 0;
  std::map<uint16_t, uint64_t> message_index_offsets;
  uint64_t message_index_length = 0;
  std::string compression;
  uint64_t compressed_size = 0, uncompressed_size = 0;
};
struct Statistics {
  uint64_t message_count = 0;
  uint16_t schema_count = 0;
  uint32_t channel_count = 0, attachment_count = 0, metadata_count = 0, chunk_count = 0;
  uint64_t message_start_time = 0, message_end_time = 0;
  std::map<uint16_t, uint64_t> channel_message_counts;
};
struct Metadata {
  std::string name;
  std::map<std::string, std::string> metadata;
};
struct MetadataIndex {
  uint64_t offset = 0, length = 0;  // of the Metadata record, prefix included
  std::string name;
};
struct SummaryOffset {
  Op group_opcode = Op::kSchema;
  uint64_t group_start = 0, group_length = 0;
};
struct Footer {
  uint64_t summary_start = 0, summary_offset_start = 0;
  uint32_t summary_crc = 0;
};
inline constexpr size_t kFooterRecordSize = kRecordPrefix + 8 + 8 + 4;
inline constexpr size_t kDataEndRecordSize = kRecordPrefix + 4;

// Appends records to `out`, each whole (prefix, content).
void append(std::string& out, const Header& record);
void append(std::string& out, const Schema& record);
void append(std::string& out, const Channel& record);
void append_message(std::string& out, const MessageHeader& header, std::span<const uint8_t> data);
void append(std::string& out, const Chunk& record);
void append(std::string& out, const MessageIndex& record);
void append(std::string& out, const ChunkIndex& record);
void append(std::string& out, const Statistics& record);
void append(std::string& out, const Metadata& record);
void append(std::string& out, const MetadataIndex& record);
void append(std::string& out, const SummaryOffset& record);
void append_data_end(std::string& out, uint32_t data_section_crc);
void append(std::string& out, const Footer& record);

// A record or field that does not fit the bytes it is in.
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One record of a byte range: its opcode and content, and where the next begins.
struct RawRecord {
  uint8_t opcode = 0;
  std::string_view content;
};
// The record at `offset` of `bytes`, or nullopt when fewer bytes remain than it needs (a file
// cut short). `offset` moves past it.
std::optional<RawRecord> next_record(std::string_view bytes, size_t& offset);

// Parsers of a record's content. Throw FormatError naming the record and the field.
Header parse_header(std::string_view content);
Schema parse_schema(std::string_view content);
Channel parse_channel(std::string_view content);
// The fields, and the data in `data` (a view into `content`).
MessageHeader parse_message(std::string_view content, std::string_view& data);
Chunk parse_chunk(std::string_view content);
MessageIndex parse_message_index(std::string_view content);
ChunkIndex parse_chunk_index(std::string_view content);
Statistics parse_statistics(std::string_view content);
Metadata parse_metadata(std::string_view content);
MetadataIndex parse_metadata_index(std::string_view content);
SummaryOffset parse_summary_offset(std::string_view content);
uint32_t parse_data_end(std::string_view content);
Footer parse_footer(std::string_view content);

}  // namespace mocap::bag::mcap
