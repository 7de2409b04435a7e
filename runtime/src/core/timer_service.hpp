// Timers, periodic or one-shot: one thread marks them due; their callbacks run on the component
// strands.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "core/executor.hpp"

namespace mocap {

class TimerService;

class Timer final : public Waitable {
 public:
  enum class Repeat { Periodic, Once };

  // Due every `period`; Once: a single time, `period` after it starts.
  Timer(std::string label, std::chrono::nanoseconds period, std::function<void()> callback,
        Strand& strand, Repeat repeat = Repeat::Periodic)
      : Waitable(std::move(label)),
        period_(period),
        repeat_(repeat),
        callback_(std::move(callback)),
        strand_(strand) {}

  bool execute_one() override;
  std::chrono::nanoseconds period() const { return period_; }
  // Ticks that found the previous one still waiting to run.
  uint64_t overruns() const { return overruns_.load(); }

 private:
  friend class TimerService;
  void fire();

  std::chrono::nanoseconds period_;
  Repeat repeat_;
  std::function<void()> callback_;
  Strand& strand_;
  std::atomic<bool> due_{false};
  std::atomic<uint64_t> overruns_{0};
  std::chrono::steady_clock::time_point next_;
};

class TimerService {
 public:
  TimerService() = default;
  ~TimerService();
  TimerService(const TimerService&) = delete;
  TimerService& operator=(const TimerService&) = delete;

  // The first tick is one period after start() (or after add(), if started).
  void add(std::shared_ptr<Timer> timer);
  void remove(const Timer* timer);
  void start();
  void stop();

 private:
  void run();

  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::shared_ptr<Timer>> timers_;
  bool running_ = false;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace mocap
