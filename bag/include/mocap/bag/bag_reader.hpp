// Reads a bag written by BagWriter or by ROS 2's rosbag2, in either storage, told apart by
// content: MCAP (profile ros2) or sqlite3 (schema versions 1 to 4). A bag directory (with or
// without metadata.yaml) or one .mcap or .db3 file.
//
//   BagReader reader("runs/walk");
//   for (const BagTopic& topic : reader.metadata().topics) ...
//   BagMessage message;
//   while (reader.next(message)) publish(message.topic->name, message.data);
//   for (const std::string& problem : reader.problems()) warn(problem);
//
// Damaged bags: what is readable is read. A truncated or corrupt database gives the messages
// its intact pages hold, an MCAP file those of its readable chunks up to a cut; each part that
// cannot be read is reported once in problems() (file, which messages or byte, why) rather
// than thrown. Only a bag with nothing readable at all
// throws. A metadata.yaml that does not parse (or lists files that are missing) is reported the
// same way, naming the file and key, and the directory's .mcap and .db3 files are read instead.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <mocap/bag/bag_error.hpp>
#include <mocap/bag/bag_metadata.hpp>

namespace mocap::bag {

struct BagMessage {
  const BagTopic* topic = nullptr;  // into metadata().topics
  int64_t timestamp_ns = 0;
  std::vector<uint8_t> data;  // serialized as topic->serialization_format says (cdr)
};

class BagReader {
 public:
  // Throws BagError when `path` is neither a bag directory nor a readable .mcap or .db3 file.
  explicit BagReader(const std::string& path);
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  // Counted from the databases, not taken from metadata.yaml (which a killed recorder
  // leaves stale).
  const BagMetadata& metadata() const;

  // Only these topics from now on (empty: all). Unknown names are ignored.
  void set_topic_filter(const std::vector<std::string>& topics);
  // The next message in timestamp order (equal stamps: in the order written); false at the
  // end.
  bool next(BagMessage& message);
  // Back to the first message (for looped playback).
  void rewind();

  // What could not be read, one line each: "walk_0.db3: messages after 12:03:04.512 (about
  // 40) unreadable: database disk image is malformed".
  const std::vector<std::string>& problems() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::bag
