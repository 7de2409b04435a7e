#include "mcap_format.hpp"

#include <array>
#include <cstring>

#include <fmt/format.h>
#include <zlib.h>

namespace mocap::bag::mcap {
namespace {

// ---- writing ----------------------------------------------------------------------------

void put_u8(std::string& out, uint8_t v) { out.push_back(static_cast<char>(v)); }
template <class T>
void put_le(std::string& out, T v) {
  for (size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}
void put_string(std::string& out, std::string_view s) {
  put_le<uint32_t>(out, static_cast<uint32_t>(s.size()));
  out.append(s);
}
void put_map(std::string& out, const std::map<std::string, std::string>& map) {
  std::string entries;
  for (const auto& [key, value] : map) {
    put_string(entries, key);
    put_string(entries, value);
  }
  put_string(out, entries);
}
template <class Value>
void put_id_map(std::string& out, const std::map<uint16_t, Value>& map) {
  put_le<uint32_t>(out, static_cast<uint32_t>(map.size() * (2 + sizeof(Value))));
  for (const auto& [key, value] : map) {
    put_le<uint16_t>(out, key);
    put_le<Value>(out, value);
  }
}

// A record being appended: its opcode now, its length once its content is in (at the end of
// the scope).
class Record {
 public:
  Record(std::string& out, Op op) : out_(out), start_(out.size()) {
    put_u8(out, static_cast<uint8_t>(op));
    put_le<uint64_t>(out, 0);
  }
  ~Record() {
    uint64_t length = out_.size() - start_ - kRecordPrefix;
    for (size_t i = 0; i < 8; ++i) {
      out_[start_ + 1 + i] = static_cast<char>((length >> (8 * i)) & 0xFF);
    }
  }
  Record(const Record&) = delete;
  Record& operator=(const Record&) = delete;

 private:
  std::string& out_;
  size_t start_;
};

// ---- reading ----------------------------------------------------------------------------

// Reads fields out of one record's content; errors name the record and the field.
class Fields {
 public:
  Fields(std::string_view content, const char* record) : content_(content), record_(record) {}

  template <class T>
  T le(const char* field) {
    need(sizeof(T), field);
    uint64_t v = 0;
    for (size_t i = 0; i < sizeof(T); ++i) {
      v |= static_cast<uint64_t>(static_cast<uint8_t>(content_[at_ + i])) << (8 * i);
    }
    at_ += sizeof(T);
    return static_cast<T>(v);
  }
  std::string_view bytes(size_t size, const char* field) {
    need(size, field);
    std::string_view out = content_.substr(at_, size);
    at_ += size;
    return out;
  }
  std::string string(const char* field) {
    const uint32_t size = le<uint32_t>(field);
    return std::string(bytes(size, field));
  }
  std::map<std::string, std::string> map(const char* field) {
    const uint32_t size = le<uint32_t>(field);
    Fields entries(bytes(size, field), record_);
    std::map<std::string, std::string> out;
    while (!entries.done()) {
      std::string key = entries.string(field);
      out[std::move(key)] = entries.string(field);
    }
    return out;
  }
  template <class Value>
  std::map<uint16_t, Value> id_map(const char* field) {
    const uint32_t size = le<uint32_t>(field);
    Fields entries(bytes(size, field), record_);
    std::map<uint16_t, Value> out;
    while (!entries.done()) {
      const uint16_t key = entries.le<uint16_t>(field);
      out[key] = entries.le<Value>(field);
    }
    return out;
  }
  std::string_view rest() {
    std::string_view out = content_.substr(at_);
    at_ = content_.size();
    return out;
  }
  bool done() const { return at_ == content_.size(); }

 private:
  void need(size_t size, const char* field) const {
    if (content_.size() - at_ < size) {
      throw FormatError(fmt::format("{}.{}: {} bytes needed, {} left in the record", record_, field,
                                    size, content_.size() - at_));
    }
  }

  std::string_view content_;
  const char* record_;
  size_t at_ = 0;
};

}  // namespace

uint32_t crc32(std::span<const uint8_t> bytes, uint32_t crc) {
  // zlib's: MCAP's CRC is zlib's CRC-32, and zlib computes it several bytes at a time (a
  // byte-wise table took 2-3 ms per image, more than writing it).
  return static_cast<uint32_t>(::crc32_z(crc, bytes.data(), bytes.size()));
}

uint32_t crc32(std::string_view bytes, uint32_t crc) {
  return crc32(std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), crc);
}

void append(std::string& out, const Header& record) {
  Record r(out, Op::kHeader);
  put_string(out, record.profile);
  put_string(out, record.library);
}

void append(std::string& out, const Schema& record) {
  Record r(out, Op::kSchema);
  put_le(out, record.id);
  put_string(out, record.name);
  put_string(out, record.encoding);
  put_string(out, record.data);
}

void append(std::string& out, const Channel& record) {
  Record r(out, Op::kChannel);
  put_le(out, record.id);
  put_le(out, record.schema_id);
  put_string(out, record.topic);
  put_string(out, record.message_encoding);
  put_map(out, record.metadata);
}

void append_message(std::string& out, const MessageHeader& header, std::span<const uint8_t> data) {
  Record r(out, Op::kMessage);
  put_le(out, header.channel_id);
  put_le(out, header.sequence);
  put_le(out, header.log_time);
  put_le(out, header.publish_time);
  out.append(reinterpret_cast<const char*>(data.data()), data.size());
}

void append(std::string& out, const Chunk& record) {
  Record r(out, Op::kChunk);
  put_le(out, record.message_start_time);
  put_le(out, record.message_end_time);
  put_le(out, record.uncompressed_size);
  put_le(out, record.uncompressed_crc);
  put_string(out, record.compression);
  put_le<uint64_t>(out, record.records.size());
  out.append(record.records);
}

void append(std::string& out, const MessageIndex& record) {
  Record r(out, Op::kMessageIndex);
  put_le(out, record.channel_id);
  put_le<uint32_t>(out, static_cast<uint32_t>(record.entries.size() * 16));
  for (const auto& [time, offset] : record.entries) {
    put_le(out, time);
    put_le(out, offset);
  }
}

void append(std::string& out, const ChunkIndex& record) {
  Record r(out, Op::kChunkIndex);
  put_le(out, record.message_start_time);
  put_le(out, record.message_end_time);
  put_le(out, record.chunk_start_offset);
  put_le(out, record.chunk_length);
  put_id_map(out, record.message_index_offsets);
  put_le(out, record.message_index_length);
  put_string(out, record.compression);
  put_le(out, record.compressed_size);
  put_le(out, record.uncompressed_size);
}

void append(std::string& out, const Statistics& record) {
  Record r(out, Op::kStatistics);
  put_le(out, record.message_count);
  put_le(out, record.schema_count);
  put_le(out, record.channel_count);
  put_le(out, record.attachment_count);
  put_le(out, record.metadata_count);
  put_le(out, record.chunk_count);
  put_le(out, record.message_start_time);
  put_le(out, record.message_end_time);
  put_id_map(out, record.channel_message_counts);
}

void append(std::string& out, const Metadata& record) {
  Record r(out, Op::kMetadata);
  put_string(out, record.name);
  put_map(out, record.metadata);
}

void append(std::string& out, const MetadataIndex& record) {
  Record r(out, Op::kMetadataIndex);
  put_le(out, record.offset);
  put_le(out, record.length);
  put_string(out, record.name);
}

void append(std::string& out, const SummaryOffset& record) {
  Record r(out, Op::kSummaryOffset);
  put_u8(out, static_cast<uint8_t>(record.group_opcode));
  put_le(out, record.group_start);
  put_le(out, record.group_length);
}

void append_data_end(std::string& out, uint32_t data_section_crc) {
  Record r(out, Op::kDataEnd);
  put_le(out, data_section_crc);
}

void append(std::string& out, const Footer& record) {
  Record r(out, Op::kFooter);
  put_le(out, record.summary_start);
  put_le(out, record.summary_offset_start);
  put_le(out, record.summary_crc);
}

std::optional<RawRecord> next_record(std::string_view bytes, size_t& offset) {
  if (offset > bytes.size() || bytes.size() - offset < kRecordPrefix) return std::nullopt;
  uint64_t length = 0;
  for (size_t i = 0; i < 8; ++i) {
    length |= static_cast<uint64_t>(static_cast<uint8_t>(bytes[offset + 1 + i])) << (8 * i);
  }
  if (bytes.size() - offset - kRecordPrefix < length) return std::nullopt;
  RawRecord record{static_cast<uint8_t>(bytes[offset]),
                   bytes.substr(offset + kRecordPrefix, static_cast<size_t>(length))};
  offset += kRecordPrefix + static_cast<size_t>(length);
  return record;
}

Header parse_header(std::string_view content) {
  Fields f(content, "Header");
  Header out;
  out.profile = f.string("profile");
  out.library = f.string("library");
  return out;
}

Schema parse_schema(std::string_view content) {
  Fields f(content, "Schema");
  Schema out;
  out.id = f.le<uint16_t>("id");
  out.name = f.string("name");
  out.encoding = f.string("encoding");
  out.data = f.string("data");
  return out;
}

Channel parse_channel(std::string_view content) {
  Fields f(content, "Channel");
  Channel out;
  out.id = f.le<uint16_t>("id");
  out.schema_id = f.le<uint16_t>("schema_id");
  out.topic = f.string("topic");
  out.message_encoding = f.string("message_encoding");
  out.metadata = f.map("metadata");
  return out;
}

MessageHeader parse_message(std::string_view content, std::string_view& data) {
  Fields f(content, "Message");
  MessageHeader out;
  out.channel_id = f.le<uint16_t>("channel_id");
  out.sequence = f.le<uint32_t>("sequence");
  out.log_time = f.le<uint64_t>("log_time");
  out.publish_time = f.le<uint64_t>("publish_time");
  data = f.rest();
  return out;
}

Chunk parse_chunk(std::string_view content) {
  Fields f(content, "Chunk");
  Chunk out;
  out.message_start_time = f.le<uint64_t>("message_start_time");
  out.message_end_time = f.le<uint64_t>("message_end_time");
  out.uncompressed_size = f.le<uint64_t>("uncompressed_size");
  out.uncompressed_crc = f.le<uint32_t>("uncompressed_crc");
  out.compression = f.string("compression");
  const uint64_t size = f.le<uint64_t>("records");
  if (size > content.size()) throw FormatError("Chunk.records: longer than the record");
  out.records = f.bytes(static_cast<size_t>(size), "records");
  return out;
}

MessageIndex parse_message_index(std::string_view content) {
  Fields f(content, "MessageIndex");
  MessageIndex out;
  out.channel_id = f.le<uint16_t>("channel_id");
  const uint32_t size = f.le<uint32_t>("records");
  if (size % 16 != 0) throw FormatError("MessageIndex.records: not a whole number of entries");
  Fields entries(f.bytes(size, "records"), "MessageIndex");
  while (!entries.done()) {
    const uint64_t time = entries.le<uint64_t>("records");
    out.entries.emplace_back(time, entries.le<uint64_t>("records"));
  }
  return out;
}

ChunkIndex parse_chunk_index(std::string_view content) {
  Fields f(content, "ChunkIndex");
  ChunkIndex out;
  out.message_start_time = f.le<uint64_t>("message_start_time");
  out.message_end_time = f.le<uint64_t>("message_end_time");
  out.chunk_start_offset = f.le<uint64_t>("chunk_start_offset");
  out.chunk_length = f.le<uint64_t>("chunk_length");
  out.message_index_offsets = f.id_map<uint64_t>("message_index_offsets");
  out.message_index_length = f.le<uint64_t>("message_index_length");
  out.compression = f.string("compression");
  out.compressed_size = f.le<uint64_t>("compressed_size");
  out.uncompressed_size = f.le<uint64_t>("uncompressed_size");
  return out;
}

Statistics parse_statistics(std::string_view content) {
  Fields f(content, "Statistics");
  Statistics out;
  out.message_count = f.le<uint64_t>("message_count");
  out.schema_count = f.le<uint16_t>("schema_count");
  out.channel_count = f.le<uint32_t>("channel_count");
  out.attachment_count = f.le<uint32_t>("attachment_count");
  out.metadata_count = f.le<uint32_t>("metadata_count");
  out.chunk_count = f.le<uint32_t>("chunk_count");
  out.message_start_time = f.le<uint64_t>("message_start_time");
  out.message_end_time = f.le<uint64_t>("message_end_time");
  out.channel_message_counts = f.id_map<uint64_t>("channel_message_counts");
  return out;
}

Metadata parse_metadata(std::string_view content) {
  Fields f(content, "Metadata");
  Metadata out;
  out.name = f.string("name");
  out.metadata = f.map("metadata");
  return out;
}

MetadataIndex parse_metadata_index(std::string_view content) {
  Fields f(content, "MetadataIndex");
  MetadataIndex out;
  out.offset = f.le<uint64_t>("offset");
  out.length = f.le<uint64_t>("length");
  out.name = f.string("name");
  return out;
}

SummaryOffset parse_summary_offset(std::string_view content) {
  Fields f(content, "SummaryOffset");
  SummaryOffset out;
  out.group_opcode = static_cast<Op>(f.le<uint8_t>("group_opcode"));
  out.group_start = f.le<uint64_t>("group_start");
  out.group_length = f.le<uint64_t>("group_length");
  return out;
}

uint32_t parse_data_end(std::string_view content) {
  Fields f(content, "DataEnd");
  return f.le<uint32_t>("data_section_crc");
}

Footer parse_footer(std::string_view content) {
  Fields f(content, "Footer");
  Footer out;
  out.summary_start = f.le<uint64_t>("summary_start");
  out.summary_offset_start = f.le<uint64_t>("summary_offset_start");
  out.summary_crc = f.le<uint32_t>("summary_crc");
  return out;
}

}  // namespace mocap::bag::mcap
