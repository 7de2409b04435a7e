#include "mcap_reader.hpp"

#include <fcntl.h>
#include <lz4frame.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>
#include <mocap/bag/bag_error.hpp>

namespace mocap::bag::mcap {
namespace {

// A chunk's records may not claim more than this uncompressed: a chunk holds one message at
// least, and no message of a robot's topics comes near it.
constexpr uint64_t kMaxChunk = 1ull << 30;

// The size the compressed frame itself declares, if it does (mcap-cpp's lz4 frames do not),
// which must then be the chunk's: a corrupt size is refused before anything is allocated.
std::optional<uint64_t> declared_size(std::string_view data, const std::string& compression) {
  if (compression == "zstd") {
    const unsigned long long size = ZSTD_getFrameContentSize(data.data(), data.size());
    if (size == ZSTD_CONTENTSIZE_ERROR) throw FormatError("zstd: not a zstd frame");
    if (size == ZSTD_CONTENTSIZE_UNKNOWN) return std::nullopt;
    return size;
  }
  LZ4F_dctx* context = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) {
    throw FormatError("lz4: no decompression context");
  }
  LZ4F_frameInfo_t info = LZ4F_INIT_FRAMEINFO;
  size_t consumed = data.size();
  const size_t result = LZ4F_getFrameInfo(context, &info, data.data(), &consumed);
  LZ4F_freeDecompressionContext(context);
  if (LZ4F_isError(result)) throw FormatError(std::string("lz4: ") + LZ4F_getErrorName(result));
  if (info.contentSize == 0) return std::nullopt;
  return info.contentSize;
}

std::string decompress(std::string_view data, const std::string& compression, uint64_t size) {
  if (size > kMaxChunk) {
    throw FormatError(fmt::format("Chunk.uncompressed_size: {} bytes is beyond belief", size));
  }
  if ((compression == "zstd" || compression == "lz4") &&
      declared_size(data, compression).value_or(size) != size) {
    throw FormatError(
        fmt::format("{}: the frame's size is not the chunk's ({} bytes)", compression, size));
  }
  std::string out(static_cast<size_t>(size), '\0');
  if (compression == "zstd") {
    const size_t got = ZSTD_decompress(out.data(), out.size(), data.data(), data.size());
    if (ZSTD_isError(got)) throw FormatError(std::string("zstd: ") + ZSTD_getErrorName(got));
    if (got != size) {
      throw FormatError(fmt::format("zstd: {} bytes, the chunk says {}", got, size));
    }
  } else if (compression == "lz4") {
    LZ4F_dctx* context = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&context, LZ4F_VERSION))) {
      throw FormatError("lz4: no decompression context");
    }
    size_t out_size = out.size(), in_size = data.size();
    const size_t left =
        LZ4F_decompress(context, out.data(), &out_size, data.data(), &in_size, nullptr);
    LZ4F_freeDecompressionContext(context);
    if (LZ4F_isError(left)) throw FormatError(std::string("lz4: ") + LZ4F_getErrorName(left));
    if (left != 0 || out_size != size) {
      throw FormatError(fmt::format("lz4: {} bytes, the chunk says {}", out_size, size));
    }
  } else if (compression.empty()) {
    if (data.size() != size) {
      throw FormatError(
          fmt::format("Chunk.records: {} bytes, the chunk says {}", data.size(), size));
    }
    out.assign(data);
  } else {
    throw FormatError(fmt::format("Chunk.compression: '{}' is not zstd, lz4 or none", compression));
  }
  return out;
}

}  // namespace

FileReader::FileReader(std::string path) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) throw BagError(fmt::format("{}: cannot open: {}", path_, std::strerror(errno)));
  struct stat status {};
  if (fstat(fd_, &status) != 0) {
    const int error = errno;
    ::close(fd_);
    throw BagError(fmt::format("{}: cannot read: {}", path_, std::strerror(error)));
  }
  size_ = static_cast<uint64_t>(status.st_size);
  try {
    scan();
  } catch (...) {
    ::close(fd_);
    throw;
  }
}

FileReader::~FileReader() {
  if (fd_ >= 0) ::close(fd_);
}

std::string FileReader::read_at(uint64_t offset, uint64_t size) const {
  if (offset >= size_) return {};
  size = std::min(size, size_ - offset);
  std::string out(static_cast<size_t>(size), '\0');
  size_t done = 0;
  while (done < out.size()) {
    const ssize_t got =
        pread(fd_, out.data() + done, out.size() - done, static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw BagError(fmt::format("{}: cannot read: {}", path_, std::strerror(errno)));
    if (got == 0) break;
    done += static_cast<size_t>(got);
  }
  out.resize(done);
  return out;
}

void FileReader::problem(uint64_t offset, const std::string& what) {
  problems_.push_back(fmt::format("{}: byte {}: {}", path_, offset, what));
}

std::string FileReader::unpack(std::string_view content) const {
  const Chunk chunk = parse_chunk(content);
  std::string records = decompress(chunk.records, chunk.compression, chunk.uncompressed_size);
  if (chunk.uncompressed_crc != 0 && crc32(records) != chunk.uncompressed_crc) {
    throw FormatError("the chunk's CRC does not match its records");
  }
  return records;
}

void FileReader::add_channel(Channel channel, uint64_t file_offset) {
  auto [known, added] = channels_.emplace(channel.id, channel);
  if (!added &&
      (known->second.topic != channel.topic || known->second.schema_id != channel.schema_id ||
       known->second.message_encoding != channel.message_encoding)) {
    problem(file_offset, fmt::format("channel {} declared again as another topic ('{}', was "
                                     "'{}'): the first kept",
                                     channel.id, channel.topic, known->second.topic));
  }
}

void FileReader::index_chunk(const std::string& records, uint32_t chunk, uint64_t file_offset) {
  // Whole or not at all: a chunk whose records do not parse adds nothing.
  std::vector<MessagePlace> found;
  std::vector<Schema> schemas;
  std::vector<Channel> channels;
  size_t offset = 0;
  while (offset < records.size()) {
    const size_t at = offset;
    const std::optional<RawRecord> record = next_record(records, offset);
    if (!record) throw FormatError(fmt::format("a record at {} runs past the chunk's end", at));
    switch (static_cast<Op>(record->opcode)) {
      case Op::kSchema:
        schemas.push_back(parse_schema(record->content));
        break;
      case Op::kChannel:
        channels.push_back(parse_channel(record->content));
        break;
      case Op::kMessage: {
        std::string_view data;
        const MessageHeader header = parse_message(record->content, data);
        found.push_back({header.log_time, header.channel_id, chunk, at});
        break;
      }
      default:
        break;  // private records and future ones
    }
  }
  for (Schema& schema : schemas) schemas_.emplace(schema.id, std::move(schema));
  for (Channel& channel : channels) add_channel(std::move(channel), file_offset);
  messages_.insert(messages_.end(), found.begin(), found.end());
}

// One pass over every record of a file without a summary. Kept whole (about 90 lines): a
// switch over the record kinds, each case a few lines.
void FileReader::scan() {
  const std::string start = read_at(0, kMagic.size());
  if (start != kMagic) {
    throw BagError(
        fmt::format("{}: not an MCAP file (it does not begin with MCAP's magic)", path_));
  }
  uint64_t offset = kMagic.size();
  bool header_seen = false;
  while (offset < size_) {
    const std::string prefix = read_at(offset, kRecordPrefix);
    if (prefix.size() < kRecordPrefix) {
      problem(offset, "the file ends inside a record's prefix (cut short)");
      break;
    }
    const auto opcode = static_cast<uint8_t>(prefix[0]);
    uint64_t length = 0;
    for (size_t i = 0; i < 8; ++i) {
      length |= static_cast<uint64_t>(static_cast<uint8_t>(prefix[1 + i])) << (8 * i);
    }
    const uint64_t content_offset = offset + kRecordPrefix;
    if (length > size_ - content_offset) {
      if (opcode == static_cast<uint8_t>(Op::kChunk)) {
        problem(offset, fmt::format("the file ends inside a chunk (cut short: {} of its {} bytes)",
                                    size_ - content_offset, length));
      } else {
        problem(offset,
                fmt::format("the file ends inside a record (opcode 0x{:02x}; cut short)", opcode));
      }
      break;
    }
    const Op op = static_cast<Op>(opcode);
    if (!header_seen && op != Op::kHeader) {
      throw BagError(fmt::format("{}: not an MCAP file (no Header after the magic)", path_));
    }
    try {
      switch (op) {
        case Op::kHeader:
          header_ = parse_header(read_at(content_offset, length));
          header_seen = true;
          break;
        case Op::kSchema: {
          Schema schema = parse_schema(read_at(content_offset, length));
          schemas_.emplace(schema.id, std::move(schema));
          break;
        }
        case Op::kChannel:
          add_channel(parse_channel(read_at(content_offset, length)), offset);
          break;
        case Op::kMessage: {
          std::string_view data;
          const MessageHeader header =
              parse_message(read_at(content_offset, std::min<uint64_t>(length, 64)), data);
          messages_.push_back({header.log_time, header.channel_id, kOutsideChunks, offset});
          break;
        }
        case Op::kChunk: {
          const auto chunk = static_cast<uint32_t>(chunks_.size());
          chunks_.push_back({content_offset, length});
          index_chunk(unpack(read_at(content_offset, length)), chunk, offset);
          break;
        }
        case Op::kMetadata:
          metadata_.push_back(parse_metadata(read_at(content_offset, length)));
          break;
        case Op::kDataEnd:
          // The summary repeats what the data section said; a closed file ends there.
          complete_ = true;
          break;
        default:
          break;
      }
    } catch (const FormatError& e) {
      problem(offset, fmt::format("{} unreadable: {}", op == Op::kChunk ? "a chunk" : "a record",
                                  e.what()));
    }
    if (complete_) break;
    offset = content_offset + length;
  }
  if (!header_seen) throw BagError(fmt::format("{}: not an MCAP file (no Header)", path_));
  // Messages on channels never declared cannot be placed in a topic.
  size_t orphans = 0;
  std::erase_if(messages_, [&](const MessagePlace& place) {
    const bool orphan = channels_.count(place.channel_id) == 0;
    orphans += orphan ? 1 : 0;
    return orphan;
  });
  if (orphans > 0) {
    problems_.push_back(
        fmt::format("{}: {} messages on channels never declared, skipped", path_, orphans));
  }
}

std::span<const uint8_t> FileReader::data(const MessagePlace& place) {
  std::string_view content;
  if (place.chunk == kOutsideChunks) {
    const std::string prefix = read_at(place.offset, kRecordPrefix);
    uint64_t length = 0;
    for (size_t i = 0; i < 8 && i + 1 < prefix.size(); ++i) {
      length |= static_cast<uint64_t>(static_cast<uint8_t>(prefix[1 + i])) << (8 * i);
    }
    message_bytes_ = read_at(place.offset + kRecordPrefix, length);
    if (prefix.size() < kRecordPrefix || message_bytes_.size() != length) {
      throw BagError(
          fmt::format("{}: byte {}: the message is no longer there", path_, place.offset));
    }
    content = message_bytes_;
  } else {
    if (cached_chunk_ != place.chunk) {
      const ChunkPlace& chunk = chunks_.at(place.chunk);
      try {
        cached_records_ = unpack(read_at(chunk.offset, chunk.length));
      } catch (const FormatError& e) {
        cached_chunk_.reset();
        throw BagError(fmt::format("{}: byte {}: the chunk is no longer readable: {}", path_,
                                   chunk.offset - kRecordPrefix, e.what()));
      }
      cached_chunk_ = place.chunk;
    }
    size_t offset = static_cast<size_t>(place.offset);
    const std::optional<RawRecord> record = next_record(cached_records_, offset);
    if (!record) throw BagError(fmt::format("{}: a message is no longer there", path_));
    content = record->content;
  }
  std::string_view data;
  try {
    parse_message(content, data);
  } catch (const FormatError& e) {
    throw BagError(fmt::format("{}: {}", path_, e.what()));
  }
  return {reinterpret_cast<const uint8_t*>(data.data()), data.size()};
}

}  // namespace mocap::bag::mcap
