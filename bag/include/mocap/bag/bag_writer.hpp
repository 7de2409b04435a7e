// Writes a bag: a directory with one SQLite database in rosbag2's sqlite3 layout (schema
// version 3, as ROS 2 Humble writes it: tables schema, metadata, topics, messages) and
// metadata.yaml, so that `ros2 bag info/play` read it and this library reads theirs.
//
//   BagWriter writer("runs/walk");                     // runs/walk/walk_0.db3 + metadata.yaml
//   uint32_t images = writer.add_topic({"/camera/ir/image_raw", "sensor_msgs/msg/Image", "cdr",
//                                       {Qos::sensor_data()}});
//   writer.write(images, stamp_ns, cdr_bytes);           // encapsulated CDR, as on the wire
//   writer.close();
//
// Crash safety: messages are committed at least every `commit_interval` or `commit_messages`,
// whichever comes first, and a writer killed at any moment (SIGKILL) leaves a bag that opens
// and holds every committed message: what is lost is at most `commit_interval` of data.
// sqlite3: the database runs in write-ahead-log mode, a commit is a transaction. mcap: a
// commit writes the open chunk whole, so the file only ever grows by complete chunks.
// metadata.yaml is rewritten (atomically, by rename) whenever topics are added and at close;
// after a kill its counts are stale, and readers count from the database.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/bag_metadata.hpp>

namespace mocap::bag {

struct BagWriterOptions {
  // "sqlite3" (rosbag2's Humble default) or "mcap" (its default since Iron: one .mcap file,
  // messages in chunks compressed with `compression`, "zstd", "lz4" or "" for none).
  std::string storage = "sqlite3";
  std::string compression = "zstd";
  // A transaction is committed when it is this old or holds this many messages.
  std::chrono::milliseconds commit_interval{100};
  size_t commit_messages = 1000;
  // The database may not grow beyond this (0: until the disk is full). Either limit ends the
  // recording the same way: write() throws BagError saying so, and the bag stays readable
  // with everything committed before.
  uint64_t max_bytes = 0;
};

class BagWriter {
 public:
  // Creates `directory` (it must not exist, or be empty) and in it `<name>_0.db3` (or
  // `<name>_0.mcap`), <name> being the directory's last component, and metadata.yaml. Throws
  // BagError.
  explicit BagWriter(const std::string& directory, BagWriterOptions options = {});
  ~BagWriter();  // close(), errors swallowed (logged to stderr)
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  // Registers a topic (its message_count is ignored) and returns its id for write(). A topic
  // name may be added once. Throws BagError.
  uint32_t add_topic(const BagTopic& topic);
  // Appends one message. `timestamp_ns`: when it was received, nanoseconds since the epoch.
  // Throws BagError when the disk or max_bytes is full or the database fails; the message
  // names the file and the SQLite error. After such an error only close() is useful.
  void write(uint32_t topic_id, int64_t timestamp_ns, std::span<const uint8_t> data);
  // Commits the open transaction now (a recorder calls it when idle).
  void commit();
  // Commits, records the metadata in the database and metadata.yaml, and closes the file.
  // Idempotent. Throws BagError.
  void close();
  // Thread-safe, also while another thread writes: metadata.yaml with the messages committed
  // so far, for a process forced to exit before close(). Throws BagError.
  void write_committed_metadata() const;

  const std::string& directory() const;
  const BagMetadata& metadata() const;  // as written so far, counts included
  uint64_t bytes_written() const;       // message payload bytes

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::bag
