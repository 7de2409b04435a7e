// A wait inside a callback for work done elsewhere: a subscriber's room, a writer thread.
#pragma once

namespace mocap {

class Executor;

// While it exists, the calling thread waits for other code to make progress. On a thread of a
// component host's executor, the executor runs another thread in its place meanwhile, so that
// the process's other callbacks (those the wait may depend on among them) keep running however
// many callbacks wait. On any other thread it does nothing.
//
//   mocap::WaitingScope waiting;
//   room_.wait(lock, [&] { return has_room(); });
class WaitingScope {
 public:
  WaitingScope();
  ~WaitingScope();
  WaitingScope(const WaitingScope&) = delete;
  WaitingScope& operator=(const WaitingScope&) = delete;

 private:
  Executor* executor_;
};

}  // namespace mocap
