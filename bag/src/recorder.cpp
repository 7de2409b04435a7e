#include <mocap/bag/recorder.hpp>

#include <chrono>
#include <condition_variable>
#include <ctime>
#include <deque>
#include <mutex>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <mocap/message_type.hpp>
#include <mocap/waiting_scope.hpp>

namespace mocap::bag {

std::string default_bag_directory() {
  const std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char name[64];
  std::strftime(name, sizeof name, "bag_%Y_%m_%d-%H_%M_%S", &local);
  return name;
}

struct Recorder::State {
  struct Item {
    uint32_t topic;
    int64_t timestamp_ns;
    std::shared_ptr<const void> message;
    const MessageType* type;
    size_t size;
  };

  explicit State(const std::string& directory, const RecorderOptions& recorder_options)
      : options(recorder_options), writer(directory, recorder_options.writer) {}

  // Serializes and writes until closed and drained; commits whenever the queue runs dry, so
  // that a quiet topic's messages do not wait for the next one.
  void run() {
    std::vector<uint8_t> buffer;
    std::unique_lock lock(mutex);
    for (;;) {
      arrived.wait_for(lock, options.writer.commit_interval,
                       [&] { return closing || !queue.empty(); });
      if (queue.empty()) {
        if (closing) return;
        lock.unlock();
        commit();
        lock.lock();
        continue;
      }
      Item item = std::move(queue.front());
      queue.pop_front();
      queued_bytes -= item.size;
      room.notify_all();
      lock.unlock();
      write(item, buffer);
      lock.lock();
    }
  }

  void write(const Item& item, std::vector<uint8_t>& buffer) {
    if (failed()) {
      std::lock_guard guard(mutex);
      ++stats.dropped;
      return;
    }
    std::span<const uint8_t> bytes;
    if (item.type == nullptr) {
      const auto& raw = *static_cast<const std::vector<uint8_t>*>(item.message.get());
      bytes = raw;
    } else {
      try {
        // Zeroed: CDR leaves its alignment padding unwritten, and a reused buffer would put
        // bytes of earlier messages into the bag.
        buffer.assign(item.type->serialized_size(item.message.get()), 0);
        bytes = std::span(buffer.data(), item.type->serialize(item.message.get(), buffer));
      } catch (const std::exception&) {
        std::lock_guard guard(mutex);
        ++stats.dropped;
        return;
      }
    }
    try {
      {
        std::lock_guard writing(writer_mutex);
        writer.write(item.topic, item.timestamp_ns, bytes);
      }
      std::lock_guard guard(mutex);
      ++stats.written;
      stats.bytes += bytes.size();
    } catch (const BagError& e) {
      std::lock_guard guard(mutex);
      if (!first_error) first_error = e.what();
      ++stats.dropped;
    }
  }

  void commit() {
    if (failed()) return;
    try {
      std::lock_guard writing(writer_mutex);
      writer.commit();
    } catch (const BagError& e) {
      std::lock_guard guard(mutex);
      if (!first_error) first_error = e.what();
    }
  }

  bool failed() {
    std::lock_guard guard(mutex);
    return first_error.has_value();
  }

  RecorderOptions options;
  std::mutex writer_mutex;  // BagWriter is not thread-safe: the writer thread and add_topic
  BagWriter writer;
  mutable std::mutex mutex;  // the queue, the counts, the error
  std::condition_variable arrived;
  std::condition_variable room;  // for record() while the queue holds max_queued_bytes
  std::deque<Item> queue;
  size_t queued_bytes = 0;
  bool closing = false, closed = false;
  RecorderStats stats;
  std::optional<std::string> first_error;
  std::thread thread;
};

Recorder::Recorder(const std::string& directory, RecorderOptions options)
    : state_(std::make_unique<State>(directory, options)) {
  state_->thread = std::thread([state = state_.get()] { state->run(); });
}

Recorder::~Recorder() {
  bool closed = false;
  {
    std::lock_guard guard(state_->mutex);
    closed = state_->closed;
  }
  // An error close() returned is the caller's to report.
  if (closed) return;
  if (auto error = close()) fmt::print(stderr, "recorder: {}\n", *error);
}

uint32_t Recorder::add_topic(const BagTopic& topic) {
  BagTopic described = topic;
  if (described.type_definition.empty()) {
    if (const MessageType* type = find_message_type(topic.type)) {
      described.type_definition = ros2idl_schema(type->name(), full_definition(*type));
    }
  }
  std::lock_guard writing(state_->writer_mutex);
  return state_->writer.add_topic(described);
}

void Recorder::record(uint32_t topic_id, int64_t timestamp_ns, std::shared_ptr<const void> message,
                      const MessageType* type) {
  const size_t size = type == nullptr
                          ? static_cast<const std::vector<uint8_t>*>(message.get())->size()
                          : type->serialized_size(message.get());
  {
    std::unique_lock lock(state_->mutex);
    // A message larger than the whole queue goes alone.
    auto room = [&] {
      return state_->closing || state_->first_error || state_->queued_bytes == 0 ||
             state_->queued_bytes + size <= state_->options.max_queued_bytes;
    };
    if (!room()) {
      WaitingScope waiting;  // the bag_recorder's callback: other components run meanwhile
      state_->room.wait(lock, room);
    }
    if (state_->closing || state_->first_error) {
      ++state_->stats.dropped;
      return;
    }
    state_->queued_bytes += size;
    state_->queue.push_back({topic_id, timestamp_ns, std::move(message), type, size});
  }
  state_->arrived.notify_one();
}

std::optional<std::string> Recorder::close() {
  {
    std::lock_guard guard(state_->mutex);
    if (state_->closed) return state_->first_error;
    state_->closing = true;
  }
  state_->arrived.notify_one();
  state_->room.notify_all();
  if (state_->thread.joinable()) state_->thread.join();
  try {
    state_->writer.close();
  } catch (const BagError& e) {
    if (!state_->first_error) state_->first_error = e.what();
  }
  std::lock_guard guard(state_->mutex);
  state_->closed = true;
  return state_->first_error;
}

void Recorder::write_committed_metadata() const { state_->writer.write_committed_metadata(); }

std::optional<std::string> Recorder::error() const {
  std::lock_guard guard(state_->mutex);
  return state_->first_error;
}

RecorderStats Recorder::stats() const {
  std::lock_guard guard(state_->mutex);
  RecorderStats stats = state_->stats;
  stats.queued_bytes = state_->queued_bytes;
  return stats;
}

const std::string& Recorder::directory() const { return state_->writer.directory(); }

}  // namespace mocap::bag
