#include "core/timer_service.hpp"

#include <algorithm>

namespace mocap {

bool Timer::execute_one() {
  if (!due_.exchange(false)) return false;
  run_callback(callback_);
  return true;
}

void Timer::fire() {
  if (due_.exchange(true)) overruns_.fetch_add(1);
  strand_.notify();
}

TimerService::~TimerService() { stop(); }

void TimerService::add(std::shared_ptr<Timer> timer) {
  std::lock_guard lock(mutex_);
  timer->next_ = std::chrono::steady_clock::now() + timer->period_;
  timers_.push_back(std::move(timer));
  changed_.notify_one();
}

void TimerService::remove(const Timer* timer) {
  std::lock_guard lock(mutex_);
  std::erase_if(timers_, [&](const auto& t) { return t.get() == timer; });
  changed_.notify_one();
}

void TimerService::start() {
  std::lock_guard lock(mutex_);
  if (running_ || stopping_) return;
  running_ = true;
  auto now = std::chrono::steady_clock::now();
  for (auto& timer : timers_) timer->next_ = now + timer->period_;
  thread_ = std::thread([this] { run(); });
}

void TimerService::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_one();
  if (thread_.joinable()) thread_.join();
}

void TimerService::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    auto now = std::chrono::steady_clock::now();
    auto next = std::chrono::steady_clock::time_point::max();
    for (auto& timer : timers_) {
      if (timer->next_ <= now) {
        timer->fire();
        if (timer->repeat_ == Timer::Repeat::Once) {
          timer->next_ = std::chrono::steady_clock::time_point::max();
          continue;
        }
        // Keep the schedule on the period grid; ticks missed while asleep are skipped.
        timer->next_ += timer->period_;
        if (timer->next_ <= now) {
          auto missed = (now - timer->next_) / timer->period_ + 1;
          timer->next_ += missed * timer->period_;
        }
      }
      next = std::min(next, timer->next_);
    }
    if (next == std::chrono::steady_clock::time_point::max()) {
      changed_.wait(lock);
    } else {
      changed_.wait_until(lock, next);
    }
  }
}

}  // namespace mocap
