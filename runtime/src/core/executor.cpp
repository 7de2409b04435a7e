#include "core/executor.hpp"

#include <algorithm>
#include <exception>

namespace mocap {
namespace {

// The executor whose thread this is, if any.
thread_local Executor* current_executor = nullptr;
// Set while Strand::dispatch() runs callbacks on a transport's thread.
thread_local bool in_transport_dispatch = false;

}  // namespace

Executor::Executor(int threads)
    : thread_count_(threads > 0
                        ? threads
                        : std::max(1, static_cast<int>(std::thread::hardware_concurrency()))) {}

Executor::~Executor() { stop(); }

void Executor::start() {
  std::lock_guard lock(mutex_);
  if (started_ || stopping_) return;
  started_ = true;
  for (int i = 0; i < thread_count_; ++i) start_thread();
}

void Executor::start_thread() {
  threads_.emplace_back([this] {
    current_executor = this;
    work();
  });
}

void Executor::stop() {
  std::vector<std::thread> threads;
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    ready_.clear();
    threads.swap(threads_);  // no thread starts once stopping
  }
  ready_cv_.notify_all();
  for (std::thread& thread : threads) {
    if (thread.joinable()) thread.join();
  }
  std::unique_lock lock(mutex_);
  foreign_runs_done_.wait(lock, [this] { return foreign_runs_ == 0; });
}

int Executor::threads_started() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(threads_.size());
}

WaitingScope::WaitingScope() : executor_(current_executor) {
  if (executor_ == nullptr) return;
  {
    std::lock_guard lock(executor_->mutex_);
    --executor_->running_;
    ++executor_->waiting_;
    // Every thread runs or waits: one more takes this one's place, if there is work for it.
    int others_free =
        static_cast<int>(executor_->threads_.size()) - executor_->running_ - executor_->waiting_;
    if (others_free == 0 && executor_->may_take_work() && !executor_->stopping_) {
      executor_->start_thread();
    }
  }
  executor_->ready_cv_.notify_one();
}

WaitingScope::~WaitingScope() {
  if (executor_ == nullptr) return;
  std::lock_guard lock(executor_->mutex_);
  --executor_->waiting_;
  ++executor_->running_;
}

bool Executor::begin_foreign_run() {
  std::lock_guard lock(mutex_);
  if (!started_ || stopping_) return false;
  ++foreign_runs_;
  return true;
}

void Executor::end_foreign_run() {
  {
    std::lock_guard lock(mutex_);
    --foreign_runs_;
  }
  foreign_runs_done_.notify_all();
}

void Executor::schedule(Strand* strand) {
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;
    ready_.push_back(strand);
    // Threads that wait inside callbacks hold no place; without an idle thread, one more.
    int free = static_cast<int>(threads_.size()) - running_ - waiting_;
    if (started_ && free == 0 && running_ < thread_count_) start_thread();
  }
  ready_cv_.notify_one();
}

void Executor::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    ready_cv_.wait(lock, [this] { return stopping_ || may_take_work(); });
    if (stopping_) return;
    Strand* strand = ready_.front();
    ready_.pop_front();
    ++running_;
    lock.unlock();
    strand->run();
    lock.lock();
    --running_;
  }
}

void Strand::add(std::shared_ptr<Waitable> waitable) { waitables_.push_back(std::move(waitable)); }

void Strand::notify() {
  pending_.store(true);
  if (enabled_.load() && !scheduled_.exchange(true)) executor_.schedule(this);
}

void Strand::dispatch() {
  if (off_transport_threads_.load() || mean_callback_ns_.load() > kQuickCallbackNanoseconds) {
    notify();
    return;
  }
  pending_.store(true);
  if (!enabled_.load() || scheduled_.exchange(true)) return;  // queued or running already
  if (executor_.begin_foreign_run()) {
    in_transport_dispatch = true;
    run(kDispatchBudget);
    in_transport_dispatch = false;
    executor_.end_foreign_run();
  } else {
    executor_.schedule(this);  // not started yet; when stopping, this does nothing
  }
}

bool Strand::on_transport_thread() { return in_transport_dispatch; }

void Strand::enable() {
  enabled_.store(true);
  if (pending_.load() && !scheduled_.exchange(true)) executor_.schedule(this);
}

bool Strand::execute(Waitable& waitable) {
  try {
    if (!waitable.execute_one()) return false;
    int64_t mean = mean_callback_ns_.load();
    mean_callback_ns_.store(mean + (waitable.callback_ns_ - mean) / 16);
    return true;
  } catch (const std::exception& e) {
    callback_errors_.fetch_add(1);
    if (auto count = waitable.error_log_.count()) {
      logger_.error("callback for {} threw ({} time(s) since last report): {}", waitable.label(),
                    *count, e.what());
    }
  } catch (...) {
    callback_errors_.fetch_add(1);
    if (auto count = waitable.error_log_.count()) {
      logger_.error("callback for {} threw a non-standard exception ({} time(s))", waitable.label(),
                    *count);
    }
  }
  return true;
}

void Strand::run(int budget) {
  // Each pass drains every waitable; another pass is needed only for notifications that
  // arrived during this one.
  do {
    pending_.store(false);
    if (!removed_.empty()) {
      std::erase_if(waitables_, [&](const std::shared_ptr<Waitable>& waitable) {
        return std::find(removed_.begin(), removed_.end(), waitable.get()) != removed_.end();
      });
      removed_.clear();
    }
    // Index loop: a callback may add waitables to its own strand.
    for (size_t i = 0; i < waitables_.size(); ++i) {
      std::shared_ptr<Waitable> waitable = waitables_[i];
      while (execute(*waitable)) {
        if (--budget == 0) {
          executor_.schedule(this);  // stays scheduled; other strands get the thread first
          return;
        }
      }
    }
  } while (pending_.load());
  scheduled_.store(false);
  // A notification that raced with the last pass must not be lost.
  if (pending_.load() && !scheduled_.exchange(true)) executor_.schedule(this);
}

}  // namespace mocap
