// Runs component callbacks on a pool of threads, one component at a time per component.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <mocap/logger.hpp>
#include <mocap/waiting_scope.hpp>

#include "core/throttle.hpp"

namespace mocap {

class Strand;

// A source of callbacks: a subscription or a timer.
class Waitable {
 public:
  explicit Waitable(std::string label) : label_(std::move(label)) {}
  virtual ~Waitable() = default;
  // Runs at most one callback, through run_callback(); false when there was nothing to do.
  virtual bool execute_one() = 0;
  const std::string& label() const { return label_; }

 protected:
  // Runs the component's code and times it: the strand learns how long its component's
  // callbacks take, without the transport's work (taking, deserializing) around them.
  template <class Callback>
  void run_callback(Callback&& callback) {
    auto start = std::chrono::steady_clock::now();
    callback();
    callback_ns_ = std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::steady_clock::now() - start)
                       .count();
  }

 private:
  friend class Strand;
  std::string label_;
  Throttle error_log_;
  int64_t callback_ns_ = 0;  // of the last callback
};

// A pool of threads that runs ready strands in FIFO order, at most `threads` at once. A thread
// that waits inside a callback (mocap/waiting_scope.hpp: a publisher waiting for a subscriber)
// does not count: another takes its place, started if none is idle, so that the callbacks it waits
// for can run however many threads wait.
class Executor {
 public:
  explicit Executor(int threads);  // threads <= 0: one per CPU core
  ~Executor();
  Executor(const Executor&) = delete;
  Executor& operator=(const Executor&) = delete;

  void start();
  // Lets running callbacks finish (those run by other threads through Strand::dispatch()
  // too), then joins the threads. Later schedule() and dispatch() calls run nothing.
  void stop();
  void schedule(Strand* strand);
  int threads() const { return thread_count_; }

  // Brackets a strand run on a thread of another's (Strand::dispatch()); false once stopping.
  bool begin_foreign_run();
  void end_foreign_run();

  // Threads started so far, those standing in for waiting ones included.
  int threads_started() const;

 private:
  friend class WaitingScope;
  void work();
  void start_thread();  // requires mutex_
  bool may_take_work() const { return !ready_.empty() && running_ < thread_count_; }

  int thread_count_;
  mutable std::mutex mutex_;
  std::condition_variable ready_cv_;
  std::condition_variable foreign_runs_done_;
  std::deque<Strand*> ready_;
  bool started_ = false;
  bool stopping_ = false;
  int foreign_runs_ = 0;
  // Threads by state: running a strand, waiting inside one, or neither (idle or starting).
  int running_ = 0;
  int waiting_ = 0;
  std::vector<std::thread> threads_;
};

// The callbacks of one component. They run one at a time, in any executor thread; a strand
// with work is queued once however many notifications arrive.
class Strand {
 public:
  Strand(Executor& executor, const Logger& logger) : executor_(executor), logger_(logger) {}

  // Not thread-safe against run(): call while the strand cannot run, or from its callbacks.
  void add(std::shared_ptr<Waitable> waitable);
  // As add(). Let go of at the start of the strand's next pass over its waitables, so that a
  // callback may remove any waitable of its own strand, its own too.
  void remove(const Waitable* waitable) { removed_.push_back(waitable); }
  // Lets go of every waitable; for the owner's destruction.
  void clear() {
    waitables_.clear();
    removed_.clear();
  }
  // Thread-safe; called by transports and timers when a waitable may have work.
  void notify();
  // For transports that call from threads of their own (DDS listeners): runs the ready
  // callbacks right here when the strand is idle and its callbacks have been quick, which
  // saves the thread wake-up of a hand-off; otherwise as notify(). Never used for in-process
  // delivery, so that publishing never runs a subscriber's code. Quick callbacks keep the
  // transport's thread free for its other work.
  void dispatch();
  // dispatch() hands this strand's callbacks to the executor from now on: they publish where
  // they may wait for a subscriber (a transport's thread waiting inside a callback could not
  // receive the acknowledgements it waits for), or they create publishers and subscriptions
  // (Fast DDS attaches a new endpoint to its receive resources under a lock its receiving
  // thread holds while it delivers: a reader created there deadlocks that thread).
  void keep_off_transport_threads() { off_transport_threads_.store(true); }
  // True inside callbacks dispatch() runs on a transport's thread.
  static bool on_transport_thread();
  // A strand runs nothing before it is enabled, so that a component's subscriptions cannot
  // call into it before its constructor has returned. Notifications are kept until then.
  void enable();
  bool enabled() const { return enabled_.load(); }
  // Called by the executor.
  void run(int budget = kBudget);
  uint64_t callback_errors() const { return callback_errors_.load(); }

 private:
  // Callbacks before the strand yields its thread to other strands.
  static constexpr int kBudget = 64;
  // Callbacks run on a transport's thread before the rest goes to the executor.
  static constexpr int kDispatchBudget = 8;
  // Mean callback duration up to which dispatch() runs callbacks on the caller's thread.
  static constexpr int64_t kQuickCallbackNanoseconds = 100000;

  bool execute(Waitable& waitable);

  Executor& executor_;
  const Logger& logger_;
  std::vector<std::shared_ptr<Waitable>> waitables_;
  std::vector<const Waitable*> removed_;  // by remove(), until the next pass
  std::atomic<bool> enabled_{false};
  std::atomic<bool> scheduled_{false};
  std::atomic<bool> pending_{false};
  std::atomic<bool> off_transport_threads_{false};
  std::atomic<uint64_t> callback_errors_{0};
  // Moving average over about 16 callbacks; starts slow, so that a component's callbacks
  // run on a transport's thread only once they have shown to be quick.
  std::atomic<int64_t> mean_callback_ns_{2 * kQuickCallbackNanoseconds};
};

}  // namespace mocap
