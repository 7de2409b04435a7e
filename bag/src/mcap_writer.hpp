// One MCAP file written as rosbag2's MCAP storage plugin writes it: profile "ros2", messages
// in chunks (zstd, lz4 or none) each followed by its message indexes, and at close the
// summary (schemas, channels, statistics, chunk indexes, metadata index) with its offsets and
// CRC. Crash safety: the file only ever grows by whole chunks (with their schemas and channels
// inside), so a writer killed at any moment leaves every chunk flushed before readable by a
// streaming reader; what is lost is the open chunk.
#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "mcap_format.hpp"

namespace mocap::bag::mcap {

struct FileWriterOptions {
  // A chunk is closed once its records reach this many bytes, uncompressed (mcap-cpp's default
  // before 2.1, which rosbag2 uses). A larger message gets a chunk of its own.
  uint64_t chunk_size = 768 * 1024;
  std::string compression = "zstd";  // "zstd", "lz4" or "" (none)
  std::string library = "mocap-graph";
};

class FileWriter {
 public:
  // Creates `path` (it must not exist) and writes the magic and the Header. Throws BagError
  // naming the file.
  FileWriter(std::string path, FileWriterOptions options);
  ~FileWriter();  // without close(): the file stays as a killed writer would leave it
  FileWriter(const FileWriter&) = delete;
  FileWriter& operator=(const FileWriter&) = delete;

  // Ids count up from 1. The records go into the chunk of their channel's first message.
  uint16_t add_schema(const std::string& name, const std::string& encoding,
                      const std::string& data);
  uint16_t add_channel(const std::string& topic, uint16_t schema_id,
                       const std::string& message_encoding,
                       const std::map<std::string, std::string>& metadata);
  // Appends a message to the open chunk, which is written out once full. Throws BagError when
  // the file cannot be written.
  void write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time,
             std::span<const uint8_t> data);
  // Writes the open chunk (if it holds anything) and flushes it to the kernel.
  void flush();
  // A Metadata record ("rosbag2" and its serialized_metadata, as rosbag2 writes it), written
  // at close.
  void set_metadata(const std::string& name, std::map<std::string, std::string> metadata);
  // flush(), then DataEnd, the summary, the summary offsets, the Footer and the magic.
  // Idempotent. Throws BagError.
  void close();

  const std::string& path() const { return path_; }
  uint64_t file_bytes() const { return offset_; }
  // The open chunk's records, uncompressed: what the next flush() adds at most, besides its
  // message indexes.
  uint64_t open_chunk_bytes() const { return chunk_.size(); }
  // The part of what close() writes that grows with the file: an index record per chunk.
  uint64_t chunk_index_bytes() const { return chunk_index_records_.size(); }

 private:
  void write_out(const std::string& bytes);
  void close_chunk();

  std::string path_;
  FileWriterOptions options_;
  std::FILE* file_ = nullptr;
  uint64_t offset_ = 0;  // bytes written to the file
  bool closed_ = false;

  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::vector<bool> schema_written_, channel_written_;
  std::vector<Metadata> metadata_;

  // The open chunk: its records, uncompressed, and their message indexes.
  std::string chunk_;
  uint64_t chunk_start_time_ = 0, chunk_end_time_ = 0;
  std::map<uint16_t, MessageIndex> chunk_indexes_;

  // The summary's Chunk Index records, serialised as each chunk closes: a third of the memory
  // the structures took, and a recorder closes ten chunks a second (a commit closes one).
  std::string chunk_index_records_;
  Statistics statistics_;
};

}  // namespace mocap::bag::mcap
