// The executor: strands run one callback at a time, yield to others, and survive errors.
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

#include "core/executor.hpp"
#include "core/timer_service.hpp"

namespace mocap {
namespace {

// A waitable with as much work as `remaining` says (-1: endless).
class Work final : public Waitable {
 public:
  explicit Work(int remaining) : Waitable("work"), remaining_(remaining) {}
  bool execute_one() override {
    if (remaining_ == 0) return false;
    if (remaining_ > 0) --remaining_;
    ++done;
    return true;
  }
  std::atomic<int> done{0};

 private:
  std::atomic<int> remaining_;
};

bool eventually(const std::function<bool()>& condition) {
  for (int i = 0; i < 3000 && !condition(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return condition();
}

TEST(Executor, AStrandWithEndlessWorkDoesNotStarveOthers) {
  Executor executor(1);
  Logger logger("test");
  Strand busy(executor, logger), quiet(executor, logger);
  auto endless = std::make_shared<Work>(-1);
  auto single = std::make_shared<Work>(1);
  busy.add(endless);
  quiet.add(single);
  busy.enable();
  busy.notify();
  executor.start();
  quiet.enable();
  quiet.notify();
  EXPECT_TRUE(eventually([&] { return single->done == 1; }));
  executor.stop();
  EXPECT_GT(endless->done, 0);
}

// A waitable whose one callback runs `body`.
class Once final : public Waitable {
 public:
  explicit Once(std::function<void()> body) : Waitable("once"), body_(std::move(body)) {}
  bool execute_one() override {
    if (done_.exchange(true)) return false;
    run_callback(body_);
    return true;
  }

 private:
  std::function<void()> body_;
  std::atomic<bool> done_{false};
};

TEST(Executor, ACallbackWaitingForAnothersWorkLendsItsThread) {
  Executor executor(1);
  Logger logger("test");
  Strand waiter(executor, logger), worker(executor, logger);
  std::mutex mutex;
  std::condition_variable changed;
  bool work_done = false, waiter_done = false;
  // The waiter needs the worker's callback, which can only run if the executor's one thread,
  // held by the waiter, is lent to it.
  waiter.add(std::make_shared<Once>([&] {
    WaitingScope waiting;
    std::unique_lock lock(mutex);
    changed.wait_for(lock, std::chrono::seconds(30), [&] { return work_done; });
    waiter_done = work_done;
  }));
  worker.add(std::make_shared<Once>([&] {
    std::lock_guard lock(mutex);
    work_done = true;
    changed.notify_all();
  }));
  waiter.enable();
  worker.enable();
  executor.start();
  waiter.notify();
  // Usually the waiter waits by now and the worker gets a new thread; otherwise the waiter
  // finds the worker ready when it begins to wait. Either way one more thread runs it.
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  worker.notify();
  EXPECT_TRUE(eventually([&] {
    std::lock_guard lock(mutex);
    return waiter_done;
  }));
  EXPECT_EQ(executor.threads_started(), 2);
  executor.stop();
  EXPECT_EQ(executor.threads_started(), 0);  // all joined
}

TEST(Executor, NothingRunsBeforeEnable) {
  Executor executor(2);
  Logger logger("test");
  Strand strand(executor, logger);
  auto work = std::make_shared<Work>(3);
  strand.add(work);
  executor.start();
  strand.notify();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(work->done, 0);
  strand.enable();  // the notification was kept
  EXPECT_TRUE(eventually([&] { return work->done == 3; }));
}

class Thrower final : public Waitable {
 public:
  Thrower() : Waitable("thrower") {}
  bool execute_one() override {
    if (left_ == 0) return false;
    --left_;
    throw std::runtime_error("boom");
  }

 private:
  std::atomic<int> left_{5};
};

TEST(Executor, ACallbackThatThrowsIsCountedAndTheStrandGoesOn) {
  Executor executor(2);
  Logger logger("test");
  Strand strand(executor, logger);
  auto thrower = std::make_shared<Thrower>();
  auto work = std::make_shared<Work>(10);
  strand.add(thrower);
  strand.add(work);
  strand.enable();
  executor.start();
  strand.notify();
  EXPECT_TRUE(eventually([&] { return work->done == 10; }));
  EXPECT_EQ(strand.callback_errors(), 5u);
}

// A waitable that records the thread of each callback and takes `duration` to run.
class Recorder final : public Waitable {
 public:
  Recorder() : Waitable("recorder") {}
  bool execute_one() override {
    if (!due.exchange(false)) return false;
    run_callback([&] {
      std::this_thread::sleep_for(duration.load());
      std::lock_guard lock(mutex);
      threads.push_back(std::this_thread::get_id());
      on_transport_thread.push_back(Strand::on_transport_thread());
    });
    return true;
  }
  // Dispatches one callback from this thread and waits for it to end; true if it ran here.
  bool dispatch_ran_here(Strand& strand) {
    size_t before = ran();
    due = true;
    strand.dispatch();
    if (!eventually([&] { return ran() > before; })) return false;
    std::lock_guard lock(mutex);
    return threads.back() == std::this_thread::get_id();
  }
  size_t ran() {
    std::lock_guard lock(mutex);
    return threads.size();
  }
  std::atomic<bool> due{false};
  std::atomic<std::chrono::microseconds> duration{std::chrono::microseconds(0)};
  std::mutex mutex;
  std::vector<std::thread::id> threads;
  std::vector<bool> on_transport_thread;  // what Strand::on_transport_thread() said
};

class DispatchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    strand.add(recorder);
    strand.enable();
    executor.start();
  }
  // Dispatches quick callbacks until the strand runs them on this thread.
  void warm_up() {
    int handed_over = 0;
    while (!recorder->dispatch_ran_here(strand)) ASSERT_LT(++handed_over, 100);
  }

  Executor executor{2};
  Logger logger{"test"};
  Strand strand{executor, logger};
  std::shared_ptr<Recorder> recorder = std::make_shared<Recorder>();
};

TEST_F(DispatchTest, RunsCallbacksHereOnceTheyHaveShownToBeQuick) {
  EXPECT_FALSE(recorder->dispatch_ran_here(strand));  // not known to be quick yet
  warm_up();
  for (int i = 0; i < 5; ++i) EXPECT_TRUE(recorder->dispatch_ran_here(strand));
  // The callbacks can tell: run on the dispatching thread here, on the executor's before.
  std::lock_guard lock(recorder->mutex);
  EXPECT_FALSE(recorder->on_transport_thread.front());
  EXPECT_TRUE(recorder->on_transport_thread.back());
  EXPECT_FALSE(Strand::on_transport_thread());
}

TEST_F(DispatchTest, HandsSlowCallbacksToTheExecutor) {
  warm_up();
  // One slow callback still runs here; it teaches the strand that its callbacks are slow.
  recorder->duration = std::chrono::milliseconds(3);
  EXPECT_TRUE(recorder->dispatch_ran_here(strand));
  EXPECT_FALSE(recorder->dispatch_ran_here(strand));
  EXPECT_FALSE(recorder->dispatch_ran_here(strand));
}

TEST_F(DispatchTest, NeverRunsCallbacksKeptOffTransportThreadsHere) {
  warm_up();
  strand.keep_off_transport_threads();
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(recorder->dispatch_ran_here(strand));
}

TEST_F(DispatchTest, StopWaitsForACallbackRunningOnAnotherThread) {
  warm_up();
  recorder->duration = std::chrono::milliseconds(200);
  recorder->due = true;
  std::thread transport([&] { strand.dispatch(); });
  EXPECT_TRUE(eventually([&] { return !recorder->due; }));  // the callback has begun
  executor.stop();
  {
    std::lock_guard lock(recorder->mutex);
    EXPECT_EQ(recorder->threads.back(), transport.get_id());  // and had ended when stop() returned
  }
  transport.join();
  recorder->due = true;
  strand.dispatch();  // stopped: nothing runs
  EXPECT_TRUE(recorder->due);
}

TEST(Timers, FireOnTheirStrand) {
  Executor executor(2);
  Logger logger("test");
  Strand strand(executor, logger);
  TimerService timers;
  std::atomic<int> ticks{0};
  auto timer = std::make_shared<Timer>(
      "t", std::chrono::milliseconds(1), [&] { ++ticks; }, strand);
  strand.add(timer);
  strand.enable();
  timers.add(timer);
  executor.start();
  timers.start();
  EXPECT_TRUE(eventually([&] { return ticks >= 20; }));
  timers.stop();
  executor.stop();
  int after_stop = ticks;
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(ticks, after_stop);
}

}  // namespace
}  // namespace mocap
