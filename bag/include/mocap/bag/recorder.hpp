// Records messages into a bag from any thread without holding the caller up while the disk
// keeps pace: messages are queued as they arrive (typed messages by pointer, serialized only
// when written) and a writer thread serializes them and commits them to a BagWriter. Shared by
// `mocap_bag record` (raw CDR from DDS) and the bag_recorder component (typed messages in-process).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <mocap/bag/bag_writer.hpp>
#include <mocap/message_type.hpp>

namespace mocap::bag {

struct RecorderOptions {
  BagWriterOptions writer;
  // Messages waiting to be written may hold this many bytes (as serialized); beyond it
  // record() waits for the writer thread, so that a slow disk cannot eat the memory and, as
  // any reliable subscriber, the recording holds its publishers back rather than lose data.
  size_t max_queued_bytes = size_t{256} << 20;
};

struct RecorderStats {
  uint64_t written = 0;     // messages in the bag
  uint64_t dropped = 0;     // not written: a write error, or recorded after close()
  uint64_t bytes = 0;       // payload bytes written
  size_t queued_bytes = 0;  // waiting now
};

// "bag_YYYY_MM_DD-HH_MM_SS" in local time: the directory a recording gets when none is named.
std::string default_bag_directory();

class Recorder {
 public:
  // Creates the bag (BagWriter's rules) and starts the writer thread. Throws BagError.
  explicit Recorder(const std::string& directory, RecorderOptions options = {});
  ~Recorder();  // close(); an error it meets then goes to stderr
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Thread-safe. Returns the id for record(). A topic without a type_definition gets its
  // type's from this process's registered types (find_message_type), when it knows the type.
  uint32_t add_topic(const BagTopic& topic);
  // Thread-safe; quick unless max_queued_bytes wait to be written, then it waits for room.
  // Queues `message` of `type` (serialized by the writer thread) or, with `type` null,
  // `message` is a std::vector<uint8_t> of encapsulated CDR, written as it is.
  void record(uint32_t topic_id, int64_t timestamp_ns, std::shared_ptr<const void> message,
              const MessageType* type);
  // Writes what is queued, closes the bag and stops the thread. Idempotent. Returns the first
  // error (disk full, a message that would not serialize is only counted), if any.
  std::optional<std::string> close();

  // Thread-safe: BagWriter::write_committed_metadata(), for a forced exit.
  void write_committed_metadata() const;
  // The first write error so far ("…: the disk is full …"); after it nothing more is written.
  std::optional<std::string> error() const;
  RecorderStats stats() const;
  const std::string& directory() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace mocap::bag
