#include "mcap_writer.hpp"

#include <fcntl.h>
#include <lz4frame.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <memory>

#include <fmt/format.h>
#include <mocap/bag/bag_error.hpp>

namespace mocap::bag::mcap {
namespace {

// mcap-cpp stores a chunk as it is when compressing gains less than this: readers must accept
// uncompressed chunks anyway, and decompressing costs time for nothing.
constexpr double kWorthwhileRatio = 1.02;
constexpr size_t kSmallChunk = 1024;

std::string compress(const std::string& records, const std::string& compression) {
  std::string out;
  if (compression == "zstd") {
    // One context per writing thread, kept: a fresh one per chunk (ZSTD_compress) allocates and
    // first touches megabytes of tables each time, which took more time than compressing.
    thread_local const std::unique_ptr<ZSTD_CCtx, size_t (*)(ZSTD_CCtx*)> context(ZSTD_createCCtx(),
                                                                                  ZSTD_freeCCtx);
    if (!context) throw BagError("zstd: cannot create a compression context");
    out.resize(ZSTD_compressBound(records.size()));
    // One-shot: the frame records its content size, which some readers need.
    const size_t size =
        ZSTD_compressCCtx(context.get(), out.data(), out.size(), records.data(), records.size(), 1);
    if (ZSTD_isError(size)) throw BagError(std::string("zstd: ") + ZSTD_getErrorName(size));
    out.resize(size);
  } else if (compression == "lz4") {
    // A whole LZ4 frame, as every MCAP reader's lz4 decompressor expects.
    LZ4F_preferences_t preferences = LZ4F_INIT_PREFERENCES;
    preferences.frameInfo.contentSize = records.size();
    out.resize(LZ4F_compressFrameBound(records.size(), &preferences));
    const size_t size =
        LZ4F_compressFrame(out.data(), out.size(), records.data(), records.size(), &preferences);
    if (LZ4F_isError(size)) throw BagError(std::string("lz4: ") + LZ4F_getErrorName(size));
    out.resize(size);
  }
  return out;
}

}  // namespace

FileWriter::FileWriter(std::string path, FileWriterOptions options)
    : path_(std::move(path)), options_(std::move(options)) {
  if (options_.compression != "" && options_.compression != "zstd" &&
      options_.compression != "lz4") {
    throw BagError(fmt::format("{}: unknown compression '{}' (zstd, lz4 or none)", path_,
                               options_.compression));
  }
  const int fd = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw BagError(fmt::format("{}: cannot create: {}", path_, std::strerror(errno)));
  file_ = fdopen(fd, "wb");
  if (file_ == nullptr) {
    ::close(fd);
    throw BagError(fmt::format("{}: cannot open: {}", path_, std::strerror(errno)));
  }
  std::string start(kMagic);
  append(start, Header{"ros2", options_.library});
  write_out(start);
  std::fflush(file_);
}

FileWriter::~FileWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

uint16_t FileWriter::add_schema(const std::string& name, const std::string& encoding,
                                const std::string& data) {
  const auto id = static_cast<uint16_t>(schemas_.size() + 1);
  schemas_.push_back({id, name, encoding, data});
  schema_written_.push_back(false);
  return id;
}

uint16_t FileWriter::add_channel(const std::string& topic, uint16_t schema_id,
                                 const std::string& message_encoding,
                                 const std::map<std::string, std::string>& metadata) {
  const auto id = static_cast<uint16_t>(channels_.size() + 1);
  channels_.push_back({id, schema_id, topic, message_encoding, metadata});
  channel_written_.push_back(false);
  return id;
}

void FileWriter::write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time,
                       std::span<const uint8_t> data) {
  if (closed_) throw BagError(path_ + ": write after close()");
  if (channel_id == 0 || channel_id > channels_.size()) {
    throw BagError(fmt::format("{}: no channel {}", path_, channel_id));
  }
  const size_t record_size = kRecordPrefix + kMessageHeaderSize + data.size();
  if (!chunk_.empty() && chunk_.size() + record_size > options_.chunk_size) close_chunk();

  // A chunk that would be read alone (the file killed after it) names its channel's schema and
  // channel itself the first time.
  const Channel& channel = channels_[channel_id - 1];
  if (!channel_written_[channel_id - 1]) {
    if (channel.schema_id != 0 && !schema_written_[channel.schema_id - 1]) {
      append(chunk_, schemas_[channel.schema_id - 1]);
      schema_written_[channel.schema_id - 1] = true;
    }
    append(chunk_, channel);
    channel_written_[channel_id - 1] = true;
  }
  if (chunk_indexes_.empty() || log_time < chunk_start_time_) chunk_start_time_ = log_time;
  if (chunk_indexes_.empty() || log_time > chunk_end_time_) chunk_end_time_ = log_time;
  MessageIndex& index = chunk_indexes_[channel_id];
  index.channel_id = channel_id;
  index.entries.emplace_back(log_time, chunk_.size());
  append_message(chunk_, {channel_id, 0, log_time, publish_time}, data);

  if (statistics_.message_count == 0 || log_time < statistics_.message_start_time) {
    statistics_.message_start_time = log_time;
  }
  if (statistics_.message_count == 0 || log_time > statistics_.message_end_time) {
    statistics_.message_end_time = log_time;
  }
  ++statistics_.message_count;
  ++statistics_.channel_message_counts[channel_id];
  if (chunk_.size() >= options_.chunk_size) close_chunk();
}

void FileWriter::close_chunk() {
  if (chunk_.empty()) return;
  std::string compressed;
  std::string compression = options_.compression;
  if (!compression.empty() && chunk_.size() >= kSmallChunk) {
    compressed = compress(chunk_, compression);
    if (static_cast<double>(chunk_.size()) / static_cast<double>(compressed.size()) <
        kWorthwhileRatio) {
      compression.clear();
    }
  } else {
    compression.clear();
  }
  const std::string& records = compression.empty() ? chunk_ : compressed;

  ChunkIndex index;
  index.message_start_time = chunk_start_time_;
  index.message_end_time = chunk_end_time_;
  index.chunk_start_offset = offset_;
  index.compression = compression;
  index.compressed_size = records.size();
  index.uncompressed_size = chunk_.size();

  std::string bytes;
  append(bytes, Chunk{chunk_start_time_, chunk_end_time_, chunk_.size(), crc32(chunk_), compression,
                      records});
  index.chunk_length = bytes.size();
  for (const auto& [channel_id, message_index] : chunk_indexes_) {
    index.message_index_offsets[channel_id] = offset_ + bytes.size();
    append(bytes, message_index);
  }
  index.message_index_length =
      offset_ + bytes.size() - index.chunk_start_offset - index.chunk_length;
  write_out(bytes);
  append(chunk_index_records_, index);
  ++statistics_.chunk_count;
  chunk_.clear();
  chunk_indexes_.clear();
}

void FileWriter::flush() {
  if (closed_) return;
  close_chunk();
  if (std::fflush(file_) != 0) {
    throw BagError(fmt::format("{}: cannot write: {}", path_, std::strerror(errno)));
  }
}

void FileWriter::set_metadata(const std::string& name,
                              std::map<std::string, std::string> metadata) {
  for (Metadata& existing : metadata_) {
    if (existing.name == name) {
      existing.metadata = std::move(metadata);
      return;
    }
  }
  metadata_.push_back({name, std::move(metadata)});
}

void FileWriter::close() {
  if (closed_) return;
  close_chunk();

  // Metadata records end the data section; their index is in the summary.
  std::vector<MetadataIndex> metadata_index;
  std::string tail;
  for (const Metadata& record : metadata_) {
    const uint64_t at = offset_ + tail.size();
    append(tail, record);
    metadata_index.push_back({at, offset_ + tail.size() - at, record.name});
  }
  append_data_end(tail, 0);
  write_out(tail);

  // The summary, grouped by opcode, each group's place in a SummaryOffset.
  const uint64_t summary_start = offset_;
  std::string summary;
  std::vector<SummaryOffset> offsets;
  auto group = [&](Op op, auto&& write_records) {
    const size_t start = summary.size();
    write_records();
    if (summary.size() > start) {
      offsets.push_back({op, summary_start + start, summary.size() - start});
    }
  };
  group(Op::kSchema, [&] {
    for (const Schema& schema : schemas_) append(summary, schema);
  });
  group(Op::kChannel, [&] {
    for (const Channel& channel : channels_) append(summary, channel);
  });
  statistics_.schema_count = static_cast<uint16_t>(schemas_.size());
  statistics_.channel_count = static_cast<uint32_t>(channels_.size());
  statistics_.metadata_count = static_cast<uint32_t>(metadata_.size());
  group(Op::kStatistics, [&] { append(summary, statistics_); });
  group(Op::kChunkIndex, [&] { summary += chunk_index_records_; });
  group(Op::kMetadataIndex, [&] {
    for (const MetadataIndex& index : metadata_index) append(summary, index);
  });
  const uint64_t summary_offset_start = summary_start + summary.size();
  for (const SummaryOffset& offset : offsets) append(summary, offset);

  // The summary CRC covers the summary, the offsets and the Footer up to its CRC field.
  std::string footer;
  append(footer, Footer{summary_start, summary_offset_start, 0});
  const uint32_t crc = crc32(std::string_view(footer).substr(0, footer.size() - 4), crc32(summary));
  footer.resize(footer.size() - 4);
  for (size_t i = 0; i < 4; ++i) footer.push_back(static_cast<char>((crc >> (8 * i)) & 0xFF));
  write_out(summary + footer + std::string(kMagic));
  closed_ = true;
  const bool failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (failed) throw BagError(fmt::format("{}: cannot write: {}", path_, std::strerror(errno)));
}

void FileWriter::write_out(const std::string& bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    throw BagError(fmt::format("{}: cannot write: {}", path_, std::strerror(errno)));
  }
  offset_ += bytes.size();
}

}  // namespace mocap::bag::mcap
