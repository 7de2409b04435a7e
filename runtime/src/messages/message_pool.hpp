// Message objects for a DDS reader to deserialize into.
#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include <mocap/message_type.hpp>

namespace mocap {

// An object comes back when its last user lets go of it: deserializing into a used object
// keeps its buffers, so large messages cost no allocation and no page faults each.
class MessagePool : public std::enable_shared_from_this<MessagePool> {
 public:
  explicit MessagePool(const MessageType& type) : type_(type) {}

  std::shared_ptr<void> get() {
    std::shared_ptr<void> object;
    {
      std::lock_guard lock(mutex_);
      if (!free_.empty()) {
        object = std::move(free_.back());
        free_.pop_back();
      }
    }
    if (object == nullptr) object = type_.create();
    void* raw = object.get();
    return std::shared_ptr<void>(
        raw, [pool = shared_from_this(), object](void*) mutable { pool->put(std::move(object)); });
  }

 private:
  void put(std::shared_ptr<void> object) {
    std::lock_guard lock(mutex_);
    if (free_.size() < kKept) free_.push_back(std::move(object));
  }

  static constexpr size_t kKept = 4;
  const MessageType& type_;
  std::mutex mutex_;
  std::vector<std::shared_ptr<void>> free_;
};

}  // namespace mocap
