// One process's statuses (process_diagnostics.hpp): the runtime's counts as rates, the levels
// its counts raise, the process's restarts, and each level change said once.
#include <gtest/gtest.h>

#include <algorithm>

#include "health/diagnostics/process_diagnostics.hpp"

namespace mocap::health {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using SteadyTime = ProcessDiagnostics::SteadyTime;

const SteadyTime kStart{seconds(1000)};

std::string value_of(const DiagnosticStatus& status, const std::string& key) {
  for (const auto& [k, v] : status.values) {
    if (k == key) return v;
  }
  return "(none)";
}

// cam_0 as the runtime counts it, having reported at `reported_at`.
ComponentHealth camera(SteadyTime reported_at, uint64_t images, uint64_t dropped = 0,
                       uint64_t errors = 0, uint64_t dropped_in = 0) {
  ComponentHealth health;
  health.name = "cam_0";
  health.plugin = "synthetic_ir_camera";
  health.published = {{"/volume/cam_0/image_raw", images, dropped}};
  health.received = {{"/sim/camera_pose", 1, dropped_in, 3}};
  health.callback_errors = errors;
  health.reported_at = reported_at;
  health.report.add("capture -> image sent median (ms)", "0.4");
  return health;
}

TEST(ProcessDiagnostics, RatesAreOverThePeriodSinceTheLastStatus) {
  ProcessDiagnostics diagnostics({.process = "cam_0", .host = "host-a"}, kStart);
  std::vector<DiagnosticStatus> statuses =
      diagnostics.update({camera(kStart + seconds(1), 30)}, kStart + seconds(1));
  ASSERT_EQ(statuses.size(), 2u);
  EXPECT_EQ(statuses[0].name, "cam_0");
  EXPECT_EQ(value_of(statuses[0], "restarts"), "0");
  const DiagnosticStatus& status = statuses[1];
  EXPECT_EQ(status.name, "cam_0/cam_0");
  EXPECT_EQ(status.hardware_id, "host-a");
  EXPECT_EQ(status.level, HealthLevel::ok);
  EXPECT_EQ(status.message, "OK");
  EXPECT_EQ(value_of(status, "plugin"), "synthetic_ir_camera");
  EXPECT_EQ(value_of(status, "out /volume/cam_0/image_raw (msg/s)"), "30.0");
  EXPECT_EQ(value_of(status, "in /sim/camera_pose (msg/s)"), "1.0");
  EXPECT_EQ(value_of(status, "in /sim/camera_pose waiting"), "3");
  EXPECT_EQ(value_of(status, "in /sim/camera_pose dropped"), "(none)");
  EXPECT_EQ(value_of(status, "capture -> image sent median (ms)"), "0.4");
  statuses =
      diagnostics.update({camera(kStart + milliseconds(3000), 90)}, kStart + milliseconds(3000));
  EXPECT_EQ(value_of(statuses[1], "out /volume/cam_0/image_raw (msg/s)"), "30.0");
  EXPECT_EQ(value_of(statuses[1], "in /sim/camera_pose (msg/s)"), "0.0");
}

TEST(ProcessDiagnostics, NewDropsWarnAndNewCallbackErrorsAreErrors) {
  ProcessDiagnostics diagnostics({.process = "p", .host = "h"}, kStart);
  diagnostics.update({camera(kStart + seconds(1), 30)}, kStart + seconds(1));
  std::vector<DiagnosticStatus> statuses =
      diagnostics.update({camera(kStart + seconds(2), 60, 4)}, kStart + seconds(2));
  EXPECT_EQ(statuses[1].level, HealthLevel::warn);
  EXPECT_NE(statuses[1].message.find("4 message(s) on /volume/cam_0/image_raw dropped"),
            std::string::npos)
      << statuses[1].message;
  EXPECT_EQ(value_of(statuses[1], "out /volume/cam_0/image_raw dropped"), "4");
  // No new drop: OK again, the total kept.
  statuses = diagnostics.update({camera(kStart + seconds(3), 90, 4)}, kStart + seconds(3));
  EXPECT_EQ(statuses[1].level, HealthLevel::ok);
  EXPECT_EQ(value_of(statuses[1], "out /volume/cam_0/image_raw dropped"), "4");
  statuses = diagnostics.update({camera(kStart + seconds(4), 120, 4, 2)}, kStart + seconds(4));
  EXPECT_EQ(statuses[1].level, HealthLevel::error);
  EXPECT_NE(statuses[1].message.find("2 callback(s) threw"), std::string::npos);
  // A subscriber's own drops: its queue overflowed.
  statuses = diagnostics.update({camera(kStart + seconds(5), 150, 4, 2, 7)}, kStart + seconds(5));
  EXPECT_EQ(statuses[1].level, HealthLevel::warn);
  EXPECT_NE(statuses[1].message.find("7 message(s) on /sim/camera_pose dropped before it read "
                                     "them"),
            std::string::npos)
      << statuses[1].message;
  EXPECT_EQ(value_of(statuses[1], "in /sim/camera_pose dropped"), "7");
}

TEST(ProcessDiagnostics, AComponentWhoseReportIsOldIsStale) {
  ProcessDiagnostics diagnostics({.process = "p", .host = "h", .stale_after = seconds(3)}, kStart);
  ComponentHealth stuck = camera(kStart + seconds(1), 30);
  EXPECT_EQ(diagnostics.update({stuck}, kStart + seconds(3))[1].level, HealthLevel::ok);
  const DiagnosticStatus status = diagnostics.update({stuck}, kStart + seconds(5))[1];
  EXPECT_EQ(status.level, HealthLevel::stale);
  EXPECT_NE(status.message.find("no report for 4 s"), std::string::npos) << status.message;
  // One whose callbacks never ran at all: as old as the process.
  ComponentHealth never = camera(SteadyTime{}, 0);
  ProcessDiagnostics fresh({.process = "p", .host = "h", .stale_after = seconds(3)}, kStart);
  EXPECT_EQ(fresh.update({never}, kStart + seconds(2))[1].level, HealthLevel::ok);
  EXPECT_EQ(fresh.update({never}, kStart + seconds(4))[1].level, HealthLevel::stale);
}

TEST(ProcessDiagnostics, AComponentsOwnProblemsKeepTheirLevelAndSentence) {
  ProcessDiagnostics diagnostics({.process = "compute", .host = "h"}, kStart);
  ComponentHealth fusion = camera(kStart + seconds(1), 30);
  fusion.name = "fusion";
  fusion.report.flag(HealthLevel::error, "camera cam_3 refused: its clock is 5 ms ahead");
  fusion.report.flag(HealthLevel::warn, "camera cam_1 is silent");
  const DiagnosticStatus status = diagnostics.update({fusion}, kStart + seconds(1))[1];
  EXPECT_EQ(status.level, HealthLevel::error);
  EXPECT_EQ(status.message,
            "camera cam_3 refused: its clock is 5 ms ahead; camera cam_1 is silent");
}

TEST(ProcessDiagnostics, ARestartedProcessWarnsForAMinuteAndKeepsItsCount) {
  ProcessDiagnostics diagnostics(
      {.process = "cam_1", .host = "h", .restarts = 2, .last_end = "was killed by signal 9"},
      kStart);
  DiagnosticStatus process = diagnostics.update({}, kStart + seconds(1))[0];
  EXPECT_EQ(process.level, HealthLevel::warn);
  EXPECT_EQ(value_of(process, "restarts"), "2");
  EXPECT_EQ(value_of(process, "last process"), "was killed by signal 9");
  EXPECT_NE(process.message.find("started again by mocap_launch (2 time(s)); the last process "
                                 "was killed by signal 9"),
            std::string::npos)
      << process.message;
  process = diagnostics.update({}, kStart + seconds(61))[0];
  EXPECT_EQ(process.level, HealthLevel::ok);
  EXPECT_EQ(value_of(process, "restarts"), "2");
}

TEST(ProcessDiagnostics, ALevelChangeIsSaidOnce) {
  ProcessDiagnostics diagnostics({.process = "p", .host = "h"}, kStart);
  diagnostics.update({camera(kStart + seconds(1), 30)}, kStart + seconds(1));
  EXPECT_TRUE(diagnostics.level_changes().empty());
  diagnostics.update({camera(kStart + seconds(2), 60, 1)}, kStart + seconds(2));
  ASSERT_EQ(diagnostics.level_changes().size(), 1u);
  EXPECT_EQ(diagnostics.level_changes()[0].substr(0, 23), "p/cam_0: OK -> WARN: 1 ");
  diagnostics.update({camera(kStart + seconds(3), 90, 2)}, kStart + seconds(3));
  EXPECT_TRUE(diagnostics.level_changes().empty());
  diagnostics.update({camera(kStart + seconds(4), 120, 2)}, kStart + seconds(4));
  ASSERT_EQ(diagnostics.level_changes().size(), 1u);
  EXPECT_EQ(diagnostics.level_changes()[0], "p/cam_0: WARN -> OK: OK");
}

// A stream's rate against what it should be (mocap/health.hpp), judged from the second report:
// below 90 % a warning with its cause; a stopped stream is not judged.
TEST(RateFigures, WarnsBelowTheExpectedRateFromTheSecondReportOn) {
  RateFigures rate;
  HealthReport first;
  rate.add();
  rate.report(first, "frames", 1e12, "the host is too busy");
  EXPECT_EQ(first.level, HealthLevel::ok);  // the start's period
  HealthReport slow;
  rate.add();
  rate.report(slow, "frames", 1e12, "the host is too busy");  // one frame in microseconds at most
  EXPECT_EQ(slow.level, HealthLevel::warn);
  EXPECT_NE(slow.message.find("of 1000000000000.0: the host is too busy"), std::string::npos)
      << slow.message;
  HealthReport stopped;
  rate.report(stopped, "frames", 1e12, "the host is too busy");
  EXPECT_EQ(stopped.level, HealthLevel::ok);
  EXPECT_EQ(stopped.values[1].second, "0.0");
  HealthReport fast;
  rate.add();
  rate.report(fast, "frames", 1e-3, "the host is too busy");  // one frame in less than 1000 s
  EXPECT_EQ(fast.level, HealthLevel::ok);
  EXPECT_EQ(fast.values[0], (std::pair<std::string, std::string>("frames expected (Hz)", "0.0")));
}

// Judged over the last five periods: a 30 Hz camera that stalled for a fifth of a second once
// (24 frames in one second) is not flagged; one that stays at 24 Hz is, from the period where
// the window falls below 27 Hz; once it stops, it starts a window of its own.
TEST(RateFigures, AStallOfOnePeriodIsNotAStreamTooSlow) {
  using std::chrono::seconds;
  RateFigures rate;
  std::chrono::steady_clock::time_point now{};
  auto period = [&](int frames) {
    for (int i = 0; i < frames; ++i) rate.add();
    now += seconds(1);
    HealthReport report;
    rate.report(report, "frames", 30, "the host is too busy", now);
    return report;
  };
  period(30);  // the start's
  for (int s = 0; s < 4; ++s) EXPECT_EQ(period(30).level, HealthLevel::ok);
  const HealthReport stalled = period(24);
  EXPECT_EQ(stalled.level, HealthLevel::ok) << stalled.message;
  EXPECT_EQ(stalled.values[1].second, "28.8");   // (4 x 30 + 24) / 5
  EXPECT_EQ(period(24).level, HealthLevel::ok);  // 27.6 Hz
  const HealthReport slow = period(24);          // 26.4 Hz
  EXPECT_EQ(slow.level, HealthLevel::warn);
  EXPECT_EQ(slow.message, "frames at 26.4 Hz of 30.0: the host is too busy");
  EXPECT_EQ(period(0).values[1].second, "0.0");
  const HealthReport again = period(30);
  EXPECT_EQ(again.level, HealthLevel::ok);
  EXPECT_EQ(again.values[1].second, "30.0");
}

}  // namespace
}  // namespace mocap::health
