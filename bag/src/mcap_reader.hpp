// Reads one MCAP file front to back, as a file whose writer was killed must be read: every
// record up to the end or the damage, each message's place kept in memory (a few dozen bytes a
// message), the messages themselves read on demand a chunk at a time. A chunk that cannot be
// read (its CRC, its compression, its records) is reported and skipped; the records around it
// are still read. A record cut short ends the scan (the writer was killed there).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mcap_format.hpp"

namespace mocap::bag::mcap {

struct MessagePlace {
  uint64_t log_time = 0;
  uint16_t channel_id = 0;
  // Index in the chunks the scan read, or kOutsideChunks for a message in the data section.
  uint32_t chunk = 0;
  uint64_t offset = 0;  // of the Message record: in the uncompressed chunk, or in the file
};
inline constexpr uint32_t kOutsideChunks = UINT32_MAX;

class FileReader {
 public:
  // Scans `path`. Throws BagError naming the file when it cannot be read or does not begin
  // with MCAP's magic and a Header.
  explicit FileReader(std::string path);
  ~FileReader();
  FileReader(const FileReader&) = delete;
  FileReader& operator=(const FileReader&) = delete;

  const std::string& path() const { return path_; }
  const Header& header() const { return header_; }
  const std::map<uint16_t, Schema>& schemas() const { return schemas_; }
  const std::map<uint16_t, Channel>& channels() const { return channels_; }
  const std::vector<MessagePlace>& messages() const { return messages_; }  // in file order
  const std::vector<Metadata>& metadata() const { return metadata_; }
  // The data section ended with DataEnd: the writer closed the file.
  bool complete() const { return complete_; }
  // What could not be read, one line each, naming the file and the byte.
  const std::vector<std::string>& problems() const { return problems_; }

  // The payload of the message at `place`, valid until the next call. Throws BagError when it
  // can no longer be read (the file changed since the scan).
  std::span<const uint8_t> data(const MessagePlace& place);

 private:
  struct ChunkPlace {
    uint64_t offset = 0;  // of the Chunk record's content in the file
    uint64_t length = 0;  // of that content
  };

  void scan();
  // Reads `size` bytes at `offset`; fewer at the end of the file.
  std::string read_at(uint64_t offset, uint64_t size) const;
  // The chunk's records, uncompressed and checked. Throws FormatError.
  std::string unpack(std::string_view content) const;
  void index_chunk(const std::string& records, uint32_t chunk, uint64_t file_offset);
  void add_channel(Channel channel, uint64_t file_offset);
  void problem(uint64_t offset, const std::string& what);

  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0;
  Header header_;
  std::map<uint16_t, Schema> schemas_;
  std::map<uint16_t, Channel> channels_;
  std::vector<MessagePlace> messages_;
  std::vector<Metadata> metadata_;
  std::vector<ChunkPlace> chunks_;
  bool complete_ = false;
  std::vector<std::string> problems_;

  // The chunk data() read last, uncompressed.
  std::optional<uint32_t> cached_chunk_;
  std::string cached_records_;
  std::string message_bytes_;  // a message outside chunks
};

}  // namespace mocap::bag::mcap
