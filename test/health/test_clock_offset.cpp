// Clock offsets from probe exchanges (clock_offset.hpp): NTP's arithmetic, its minimum-delay
// filter against queues that delay one way only, and the processes known by their topics.
#include <gtest/gtest.h>

#include <random>

#include "health/clock_offset/clock_offset.hpp"

namespace mocap::health {
namespace {

constexpr int64_t kMs = 1'000'000;

// An exchange with a peer whose clock is `offset_ns` ahead of ours, the probe taking `out_ns`
// and the answer `back_ns`, answered `hold_ns` after it arrived.
ClockExchange exchange(int64_t start_ns, int64_t offset_ns, int64_t out_ns, int64_t back_ns,
                       int64_t hold_ns = 20'000) {
  ClockExchange e;
  e.probe_sent_ns = start_ns;
  e.probe_received_ns = start_ns + out_ns + offset_ns;
  e.reply_sent_ns = e.probe_received_ns + hold_ns;
  e.reply_received_ns = start_ns + out_ns + hold_ns + back_ns;
  return e;
}

TEST(ClockOffset, ASymmetricExchangeGivesTheOffsetExactly) {
  const ClockExchange e = exchange(1'800'000'000 * 1'000'000'000LL, 5 * kMs, 150'000, 150'000);
  EXPECT_EQ(e.offset_ns(), 5 * kMs);
  EXPECT_EQ(e.round_trip_ns(), 300'000);
  const ClockExchange behind =
      exchange(1'800'000'000 * 1'000'000'000LL, -500 * kMs, 80'000, 80'000);
  EXPECT_EQ(behind.offset_ns(), -500 * kMs);
}

TEST(ClockOffset, AnAsymmetricExchangeIsOffByHalfTheDifference) {
  // 0.9 ms out, 0.1 ms back: the offset looks 0.4 ms larger, within half the round trip.
  const ClockExchange e = exchange(0, 2 * kMs, 900'000, 100'000);
  EXPECT_EQ(e.offset_ns(), 2 * kMs + 400'000);
  EXPECT_LE(std::abs(e.offset_ns() - 2 * kMs), e.round_trip_ns() / 2);
}

// Queues delay probes and answers at random, one way more than the other: the filter keeps the
// exchange that waited least, within 0.1 ms of the true offset when one of the last eight crossed
// quickly, where the mean of the eight is off by more than half a millisecond.
TEST(ClockOffset, TheFilterTakesTheExchangeWithTheShortestRoundTrip) {
  std::mt19937 random(7);
  std::exponential_distribution<double> queue(1.0 / (2.0 * kMs));  // 2 ms on average
  ClockOffsetFilter filter;
  EXPECT_FALSE(filter.offset());
  double mean_error = 0;
  for (int i = 0; i < 8; ++i) {
    const int64_t out = 100'000 + static_cast<int64_t>(queue(random));
    const int64_t back = i == 5 ? 100'000 : 100'000 + static_cast<int64_t>(queue(random) / 4);
    const ClockExchange e = exchange(i * 100 * kMs, 5 * kMs, i == 5 ? 100'000 : out, back);
    mean_error += static_cast<double>(e.offset_ns() - 5 * kMs) / 8;
    filter.add(e);
  }
  const std::optional<ClockOffset> offset = filter.offset();
  ASSERT_TRUE(offset);
  EXPECT_EQ(offset->samples, 8);
  EXPECT_EQ(offset->round_trip_ns, 200'000);
  EXPECT_EQ(offset->offset_ns, 5 * kMs);
  EXPECT_GT(std::abs(mean_error), 0.5 * kMs);
}

// Exchanges 10 ms apart: the quick one is kept while the last exchange is within the
// window of it, and forgotten after.
TEST(ClockOffset, TheFilterForgetsExchangesOlderThanItsWindow) {
  const int64_t window_ns = std::chrono::nanoseconds(ClockOffsetFilter::kWindow).count();
  ClockOffsetFilter filter;
  filter.add(exchange(0, 1 * kMs, 10'000, 10'000));  // the quickest, and the oldest
  const int64_t quick_received_ns = 20'000 + 10'000 + 10'000;
  constexpr int64_t kStep = 10 * kMs;
  int64_t start_ns = kStep;
  for (; start_ns + 420'000 - quick_received_ns <= window_ns; start_ns += kStep) {
    filter.add(exchange(start_ns, 3 * kMs, 200'000, 200'000));
  }
  ASSERT_TRUE(filter.offset());
  EXPECT_EQ(filter.offset()->offset_ns, 1 * kMs);
  EXPECT_EQ(filter.offset()->span_ns, start_ns - kStep + 420'000 - quick_received_ns);
  filter.add(exchange(start_ns, 3 * kMs, 200'000, 200'000));
  EXPECT_EQ(filter.offset()->offset_ns, 3 * kMs);
  EXPECT_EQ(filter.offset()->samples, static_cast<int>(window_ns / kStep));
  EXPECT_LE(filter.offset()->span_ns, window_ns);
}

// However often a peer is probed, the filter holds kMaxSamples at most.
TEST(ClockOffset, TheFilterHoldsABoundedNumberOfExchanges) {
  ClockOffsetFilter filter;
  for (size_t i = 0; i < 3 * ClockOffsetFilter::kMaxSamples; ++i) {
    filter.add(exchange(static_cast<int64_t>(i) * 1000, 0, 100'000, 100'000));
  }
  EXPECT_EQ(filter.offset()->samples, static_cast<int>(ClockOffsetFilter::kMaxSamples));
}

TEST(ClockOffset, WhatAnExchangeProvesIsTheOffsetLessHalfItsRoundTrip) {
  EXPECT_EQ((ClockOffset{5 * kMs, 400'000, 1}).least_offset_ns(), 5 * kMs - 200'000);
  EXPECT_EQ((ClockOffset{-5 * kMs, 400'000, 1}).least_offset_ns(), 5 * kMs - 200'000);
  EXPECT_EQ((ClockOffset{150'000, 400'000, 1}).least_offset_ns(), 0);
}

TEST(ClockOffset, AnExchangeWithANegativeRoundTripIsNotKept) {
  ClockOffsetFilter filter;
  ClockExchange stepped = exchange(0, 0, 100'000, 100'000);
  stepped.reply_received_ns = stepped.probe_sent_ns - 1;  // our clock stepped back meanwhile
  filter.add(stepped);
  EXPECT_FALSE(filter.offset());
}

TEST(PeerClocks, ATopicsClockIsThatOfTheProcessThatPublishesIt) {
  PeerClocks peers;
  const auto t0 = std::chrono::steady_clock::time_point(std::chrono::seconds(100));
  peers.add(1, "host-a", "cam_0", {"/volume/cam_0/fiducials", "/volume/cam_0/image_raw"},
            exchange(0, 0, 100'000, 100'000), t0);
  peers.add(2, "host-b", "cam_1", {"/volume/cam_1/fiducials"},
            exchange(0, 5 * kMs, 100'000, 100'000), t0);
  const PeerClocks::Peer* cam_1 = peers.publisher_of("/volume/cam_1/fiducials");
  ASSERT_NE(cam_1, nullptr);
  EXPECT_EQ(cam_1->host, "host-b");
  EXPECT_EQ(cam_1->filter.offset()->offset_ns, 5 * kMs);
  EXPECT_EQ(peers.publisher_of("/volume/cam_0/fiducials")->filter.offset()->offset_ns, 0);
  EXPECT_EQ(peers.publisher_of("/volume/cam_2/fiducials"), nullptr);
}

// A camera's process restarted on a host whose clock was set meanwhile: its new process is a new
// peer, and the old one's quick exchanges do not speak for it; the old one is forgotten once
// silent.
TEST(PeerClocks, ARestartedProcessIsMeasuredAfresh) {
  PeerClocks peers;
  const auto t0 = std::chrono::steady_clock::time_point(std::chrono::seconds(100));
  for (int i = 0; i < 8; ++i) {
    peers.add(1, "host-b", "cam_1", {"/volume/cam_1/fiducials"},
              exchange(i * kMs, 5 * kMs, 10'000, 10'000), t0 + std::chrono::milliseconds(100 * i));
  }
  const auto later = t0 + std::chrono::seconds(2);
  peers.add(9, "host-b", "cam_1", {"/volume/cam_1/fiducials"},
            exchange(0, 20'000, 300'000, 300'000), later);
  EXPECT_EQ(peers.publisher_of("/volume/cam_1/fiducials")->filter.offset()->offset_ns, 20'000);
  EXPECT_EQ(peers.size(), 2u);
  peers.forget_silent(later + std::chrono::seconds(2), std::chrono::seconds(3));
  EXPECT_EQ(peers.size(), 1u);
}

}  // namespace
}  // namespace mocap::health
