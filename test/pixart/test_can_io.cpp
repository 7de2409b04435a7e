// The PixArt bridge's CAN input layer (components/pixart/pixart_bridge, library can_io): frames in
// candump notation, the SLCAN protocol, candump -L logs, serial ports over real
// pseudo-terminals (components/common/serial_io), and SocketCAN (frame conversion always; a live
// round trip where a vcan0 interface exists).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <ostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/can_io/adaptor_clock.hpp"
#include "common/can_io/can_frame.hpp"
#include "common/can_io/can_source.hpp"
#include "common/can_io/candump_log.hpp"
#include "common/can_io/slcan.hpp"
#include "common/can_io/socketcan.hpp"
#include "common/serial_io/serial_port.hpp"
#include "test/test_support.hpp"

namespace mocap::can {

using serial::PseudoTerminal;
using serial::SerialError;
using serial::SerialPort;
using serial::supported_baud_rates;

// Readable frames in failure messages.
void PrintTo(const CanFrame& frame, std::ostream* out) {
  *out << to_string(frame) << " (stamp " << frame.stamp_ns << " ns)";
}

namespace {

using namespace std::chrono_literals;

// Generous: only a bound for tests that wait for bytes which should arrive at once.
constexpr auto kArrivalTimeout = 10s;

CanFrame make_frame(uint32_t id, std::vector<uint8_t> data, bool extended = false) {
  CanFrame frame;
  frame.id = id;
  frame.extended = extended;
  frame.length = static_cast<uint8_t>(data.size());
  std::copy(data.begin(), data.end(), frame.data.begin());
  return frame;
}

CanFrame make_remote(uint32_t id, uint8_t length, bool extended = false) {
  CanFrame frame;
  frame.id = id;
  frame.extended = extended;
  frame.remote = true;
  frame.length = length;
  return frame;
}

// Frames of every kind with random ids and data, reproducibly.
std::vector<CanFrame> random_frames(size_t count, uint32_t seed) {
  std::mt19937 generator(seed);
  std::vector<CanFrame> frames;
  for (size_t i = 0; i < count; ++i) {
    CanFrame frame;
    frame.extended = generator() % 2 == 0;
    frame.remote = generator() % 5 == 0;
    frame.id = generator() & (frame.extended ? kMaxExtendedId : kMaxStandardId);
    frame.length = static_cast<uint8_t>(generator() % 9);
    if (!frame.remote) {
      for (size_t b = 0; b < frame.length; ++b) frame.data[b] = static_cast<uint8_t>(generator());
    }
    frames.push_back(frame);
  }
  return frames;
}

std::vector<CanFrame> with_stamp(std::vector<CanFrame> frames, int64_t stamp_ns) {
  for (CanFrame& frame : frames) frame.stamp_ns = stamp_ns;
  return frames;
}

std::string encode_all(const std::vector<CanFrame>& frames) {
  std::string stream;
  for (const CanFrame& frame : frames) stream += encode_slcan(frame);
  return stream;
}

// The message of the exception of type E that `call` throws; fails the test if it throws none.
template <class E, class Call>
std::string error_of(Call&& call) {
  try {
    call();
  } catch (const E& error) {
    return error.what();
  }
  ADD_FAILURE() << "no exception thrown";
  return "";
}

// Reads from `source` (SerialPort or PseudoTerminal) until `expected_size` bytes came or
// kArrivalTimeout passed.
template <class Source>
std::string read_bytes(Source& source, size_t expected_size) {
  std::string received;
  const auto deadline = std::chrono::steady_clock::now() + kArrivalTimeout;
  char buffer[256];
  while (received.size() < expected_size && std::chrono::steady_clock::now() < deadline) {
    received.append(buffer, source.read(buffer, sizeof(buffer), 100ms));
  }
  return received;
}

// All 256 byte values, so that raw mode is seen to pass every one unchanged (no echo, no
// '\r' -> '\n', no XON/XOFF, no 8th bit stripped).
std::string all_byte_values() {
  std::string bytes;
  for (int value = 0; value < 256; ++value) bytes += static_cast<char>(value);
  return bytes;
}

// --- CanFrame -------------------------------------------------------------------------------

TEST(CanFrame, PrintsInCandumpNotation) {
  EXPECT_EQ(to_string(make_frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF})), "123#DEADBEEF");
  EXPECT_EQ(to_string(make_frame(0x12345678, {0x00}, true)), "12345678#00");
  EXPECT_EQ(to_string(make_frame(0x5, {0x0A, 0xB0}, true)), "00000005#0AB0");
  EXPECT_EQ(to_string(make_frame(0x7FF, {})), "7FF#");
  EXPECT_EQ(to_string(make_frame(0x1, {1, 2, 3, 4, 5, 6, 7, 8})), "001#0102030405060708");
  EXPECT_EQ(to_string(make_remote(0x123, 0)), "123#R");
  EXPECT_EQ(to_string(make_remote(0x123, 4)), "123#R4");
  EXPECT_EQ(to_string(make_remote(0x1FFFFFFF, 8, true)), "1FFFFFFF#R8");
}

TEST(CanFrame, ValidationRefusesWhatNoBusCarries) {
  EXPECT_NO_THROW(validate_frame(make_frame(0x7FF, {1, 2, 3, 4, 5, 6, 7, 8})));
  EXPECT_NO_THROW(validate_frame(make_frame(0x1FFFFFFF, {}, true)));
  const std::string too_large_id =
      error_of<std::invalid_argument>([] { validate_frame(make_frame(0x800, {})); });
  EXPECT_NE(too_large_id.find("0x800"), std::string::npos) << too_large_id;
  EXPECT_NE(too_large_id.find("standard"), std::string::npos) << too_large_id;
  EXPECT_THROW(validate_frame(make_frame(0x20000000, {}, true)), std::invalid_argument);
  CanFrame nine_bytes = make_frame(0x123, {});
  nine_bytes.length = 9;
  const std::string too_long = error_of<std::invalid_argument>([&] { validate_frame(nine_bytes); });
  EXPECT_NE(too_long.find("length 9"), std::string::npos) << too_long;
}

// --- SLCAN encoding and commands -------------------------------------------------------------

TEST(SlcanEncode, WritesLawicelMessagesInUppercaseHex) {
  EXPECT_EQ(encode_slcan(make_frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF})), "t1234DEADBEEF\r");
  EXPECT_EQ(encode_slcan(make_frame(0x12345678, {0xAA}, true)), "T123456781AA\r");
  EXPECT_EQ(encode_slcan(make_frame(0x00A, {}, false)), "t00A0\r");
  EXPECT_EQ(encode_slcan(make_frame(0xABC, {}, true)), "T00000ABC0\r");
  EXPECT_EQ(encode_slcan(make_remote(0x123, 0)), "r1230\r");
  // A remote frame has a length but never data, whatever its data array holds.
  CanFrame remote = make_remote(0x1ABCDEF0, 4, true);
  remote.data = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_EQ(encode_slcan(remote), "R1ABCDEF04\r");
}

TEST(SlcanEncode, RefusesInvalidFrames) {
  EXPECT_THROW(encode_slcan(make_frame(0x800, {})), std::invalid_argument);
  CanFrame nine_bytes = make_frame(0x123, {});
  nine_bytes.length = 9;
  EXPECT_THROW(encode_slcan(nine_bytes), std::invalid_argument);
}

TEST(SlcanCommands, OpenClosesSetsTheBitrateAndOpens) {
  EXPECT_EQ(slcan_open_commands(500000), (std::vector<std::string>{"C\r", "S6\r", "Z1\r", "O\r"}));
  const std::vector<std::pair<int, std::string>> table = {
      {10000, "S0\r"},  {20000, "S1\r"},  {50000, "S2\r"},  {100000, "S3\r"}, {125000, "S4\r"},
      {250000, "S5\r"}, {500000, "S6\r"}, {800000, "S7\r"}, {1000000, "S8\r"}};
  for (const auto& [bitrate, command] : table) {
    const std::vector<std::string> commands = slcan_open_commands(bitrate);
    ASSERT_EQ(commands.size(), 4u) << bitrate;
    EXPECT_EQ(commands[1], command) << bitrate;
  }
  EXPECT_EQ(slcan_close_command(), "C\r");
}

TEST(SlcanCommands, UnsupportedBitrateNamesTheSupportedOnes) {
  const std::string error = error_of<std::invalid_argument>([] { slcan_open_commands(300000); });
  EXPECT_NE(error.find("300000"), std::string::npos) << error;
  EXPECT_NE(error.find("10000, 20000, 50000, 100000, 125000, 250000, 500000, 800000, 1000000"),
            std::string::npos)
      << error;
  EXPECT_THROW(slcan_open_commands(0), std::invalid_argument);
  EXPECT_THROW(slcan_open_commands(-500000), std::invalid_argument);
}

// --- SLCAN parsing --------------------------------------------------------------------------

TEST(SlcanParser, RoundTripsEveryKindOfFrame) {
  const std::vector<CanFrame> frames = {
      make_frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF}),
      make_frame(0x12345678, {0xAA, 0x55}, true),
      make_frame(0x000, {}),
      make_frame(0x1FFFFFFF, {}, true),
      make_frame(0x7FF, {0, 1, 2, 3, 4, 5, 6, 0xFF}),
      make_remote(0x100, 0),
      make_remote(0x100, 8),
      make_remote(0x0ABCDEF, 3, true),
  };
  SlcanParser parser;
  parser.feed(encode_all(frames), 1234567);
  EXPECT_EQ(parser.take_frames(), with_stamp(frames, 1234567));
  EXPECT_TRUE(parser.take_frames().empty());  // taken once
  EXPECT_EQ(parser.stats().frames, frames.size());
  EXPECT_EQ(parser.stats().errors, 0u);
  EXPECT_EQ(parser.last_error(), "");
  EXPECT_EQ(parser.pending_bytes(), 0u);
}

TEST(SlcanParser, AcceptsLowercaseHexAndAdaptorTimestamps) {
  SlcanParser parser;
  parser.feed("t1ab2beef\r");       // lowercase
  parser.feed("t1232DEAD1A2B\r");   // timestamp 0x1A2B ms after the data
  parser.feed("T000000010EA5F\r");  // extended, no data, timestamp
  parser.feed("r1232ea5f\r");       // remote, timestamp
  EXPECT_EQ(parser.take_frames(),
            (std::vector<CanFrame>{make_frame(0x1AB, {0xBE, 0xEF}), make_frame(0x123, {0xDE, 0xAD}),
                                   make_frame(0x1, {}, true), make_remote(0x123, 2)}));
  EXPECT_EQ(parser.stats().errors, 0u) << parser.last_error();
}

// Frames the adaptor stamped are stamped when it received them, not when they were read.
TEST(SlcanParser, StampsFramesWithTheAdaptorsTimeOnTheHostsClock) {
  SlcanParser parser;
  parser.feed("t1232DEAD0010\r", 1'000'000'000);  // received at 16 ms, read at once
  // Two frames 4 and 8 ms later, read together 50 ms late.
  parser.feed("t1232DEAD0014\rt1232DEAD0018\r", 1'058'000'000);
  parser.feed("t1232DEAD\r", 1'060'000'000);  // no timestamp: when read
  const std::vector<CanFrame> frames = parser.take_frames();
  ASSERT_EQ(frames.size(), 4u);
  // 4 and 8 ms after the first, give or take the drift AdaptorClock allows over 58 ms.
  const double drift_ns = 58e6 * AdaptorClock::kMaxDrift;
  EXPECT_EQ(frames[0].stamp_ns, 1'000'000'000);
  EXPECT_NEAR(static_cast<double>(frames[1].stamp_ns), 1'004'000'000, drift_ns);
  EXPECT_NEAR(static_cast<double>(frames[2].stamp_ns), 1'008'000'000, drift_ns);
  EXPECT_EQ(frames[3].stamp_ns, 1'060'000'000);
}

// --- the adaptor's clock ---------------------------------------------------------------------

constexpr int64_t kMs = 1'000'000;

// A frame every 4 ms, read after delays of 0.2 to 60 ms, in bursts: every stamp is the frame's
// time on the adaptor plus the offset of the quickest read so far.
TEST(AdaptorClock, TheQuickestReadSetsTheOffsetAndDelaysDoNotShowInTheStamps) {
  AdaptorClock clock;
  std::mt19937 generator(3);
  const int64_t host_minus_adaptor = 1'700'000'000'000'000'000 - 59'000 * kMs;
  int64_t least_delay = std::numeric_limits<int64_t>::max();
  int64_t read_ns = 0;
  for (int k = 0; k < 1000; ++k) {  // 4 s from adaptor time 59 s: through the minute's wrap
    const int64_t adaptor_ns = (59'000 + 4 * k) * kMs;
    const auto adaptor_ms = static_cast<uint32_t>((adaptor_ns / kMs) % 60'000);
    // The delay of a burst's first frame; the rest are read with it.
    if (k % 10 == 0) {
      const int64_t delay = 200'000 + static_cast<int64_t>(generator() % 60'000'000);
      read_ns = std::max(read_ns, host_minus_adaptor + adaptor_ns + delay);
    }
    read_ns = std::max(read_ns, host_minus_adaptor + adaptor_ns + 200'000);
    least_delay = std::min(least_delay, read_ns - host_minus_adaptor - adaptor_ns);
    const int64_t stamp = clock.host_time(adaptor_ms, read_ns);
    EXPECT_LE(stamp, read_ns) << k;
    // The offset may have risen by the allowed drift since the quickest read (at most 4 s).
    EXPECT_NEAR(static_cast<double>(stamp - host_minus_adaptor - adaptor_ns),
                static_cast<double>(least_delay), 4e9 * AdaptorClock::kMaxDrift)
        << k;
  }
}

TEST(AdaptorClock, FollowsAnAdaptorClockSlowerThanTheHosts) {
  AdaptorClock clock;
  constexpr double kSlow = 500e-6;   // the adaptor counts 0.9995 s per host second
  for (int k = 0; k <= 2000; ++k) {  // 20 s, a frame every 10 ms, each read 1 ms after it
    const int64_t host_ns = 10 * k * kMs;
    const auto adaptor_ms =
        static_cast<uint32_t>(std::floor(static_cast<double>(host_ns) * (1 - kSlow) / kMs));
    const int64_t stamp = clock.host_time(adaptor_ms % 60'000, host_ns + kMs);
    EXPECT_LE(stamp, host_ns + kMs);
    EXPECT_GT(stamp, host_ns - 2 * kMs) << k;  // the millisecond step and the read delay
  }
}

TEST(AdaptorClock, StartsAfreshAfterASilenceOrAnUnbelievableStamp) {
  AdaptorClock clock;
  EXPECT_EQ(clock.host_time(100, 5'000 * kMs), 5'000 * kMs);
  // 4 ms later on the adaptor, read 6 ms late: 4 ms later (give or take the drift allowed).
  EXPECT_NEAR(clock.host_time(104, 5'010 * kMs), 5'004 * kMs, 10 * kMs * AdaptorClock::kMaxDrift);
  // 40 s of silence: the minutes cannot be counted; the frame is stamped when read.
  EXPECT_EQ(clock.host_time(50'000, 45'010 * kMs), 45'010 * kMs);
  EXPECT_EQ(clock.host_time(50'010, 45'020 * kMs), 45'020 * kMs);
  // A frozen adaptor clock: stamps fall behind the reads by at most kMaxDelay_ns.
  for (int64_t read = 45'030; read < 47'000; read += 10) {
    const int64_t stamp = clock.host_time(50'010, read * kMs);
    EXPECT_LE(stamp, read * kMs);
    EXPECT_GE(stamp, read * kMs - AdaptorClock::kMaxDelay_ns) << read;
  }
}

TEST(SlcanParser, FramesSplitAcrossReadsComeOutTheSame) {
  const std::vector<CanFrame> frames = random_frames(300, 7);
  const std::string stream = encode_all(frames);

  SlcanParser byte_by_byte;
  for (char byte : stream) byte_by_byte.feed(std::string_view(&byte, 1), 99);
  EXPECT_EQ(byte_by_byte.take_frames(), with_stamp(frames, 99));

  std::mt19937 generator(11);
  SlcanParser chunked;
  std::vector<CanFrame> decoded;
  for (size_t position = 0; position < stream.size();) {
    const size_t chunk = std::min<size_t>(1 + generator() % 40, stream.size() - position);
    chunked.feed(std::string_view(stream).substr(position, chunk), 99);
    position += chunk;
    // Taking frames between reads, as the bridge does, loses nothing.
    for (const CanFrame& frame : chunked.take_frames()) decoded.push_back(frame);
  }
  EXPECT_EQ(decoded, with_stamp(frames, 99));
  EXPECT_EQ(chunked.stats().frames, 300u);
  EXPECT_EQ(chunked.stats().errors, 0u) << chunked.last_error();
}

TEST(SlcanParser, StampIsTheFeedThatCompletesTheFrame) {
  SlcanParser parser;
  parser.feed("t1231", 10);
  parser.feed("AA\rt4560", 20);
  parser.feed("\r", 30);
  const std::vector<CanFrame> frames = parser.take_frames();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].stamp_ns, 20);
  EXPECT_EQ(frames[1].stamp_ns, 30);
}

TEST(SlcanParser, CountsRepliesAndBellsWithoutErrors) {
  SlcanParser parser;
  parser.feed(
      "\r\r\a"
      "z\rZ\r"
      "t1230\r\n"
      "\a");
  EXPECT_EQ(parser.take_frames(), (std::vector<CanFrame>{make_frame(0x123, {})}));
  EXPECT_EQ(parser.stats().replies, 4u);  // two empty OKs, z, Z; "\r\n" is one terminator
  EXPECT_EQ(parser.stats().bells, 2u);
  EXPECT_EQ(parser.stats().errors, 0u) << parser.last_error();
}

TEST(SlcanParser, RejectsMalformedMessagesWithTheReason) {
  struct Case {
    std::string message;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {"x123\r", "unknown message type 'x'"},
      {"V1013\r", "unknown message type 'V'"},
      {"t12\r", "3 characters are too few for a standard frame"},
      {"T1234\r", "too few for an extended frame"},
      {"t12G0\r", "bad hex digit in the id"},
      {"t8000\r", "id 0x800 is above 0x7FF"},
      {"T200000000\r", "id 0x20000000 is above 0x1FFFFFFF"},
      {"t123900112233445566778899\r", "DLC 9 is above 8"},
      {"t123X\r", "bad length digit 'X'"},
      {"t1232DEA\r", "DLC 2 needs 4 characters after it (or 8 with a timestamp), got 3"},
      {"t1232DEADBE\r", "DLC 2 needs 4 characters after it (or 8 with a timestamp), got 6"},
      {"t1231\r", "DLC 1 needs 2 characters after it (or 6 with a timestamp), got 0"},
      {"t1232DEZZ\r", "bad hex digit in data byte 1"},
      {"t1232DEAD12G4\r", "bad hex digit in the timestamp"},
      {"t1232DEADEA60\r", "timestamp 0xEA60 is past a minute's last millisecond (0xEA5F)"},
      {"r12311\r", "DLC 1 needs 0 characters after it (or 4 with a timestamp), got 1"},
      {"t1\x01\xff\r", "too few"},
      {"t12\a", "message cut off by a BELL"},
  };
  for (const Case& bad : cases) {
    SlcanParser parser;
    parser.feed(bad.message);
    EXPECT_TRUE(parser.take_frames().empty()) << bad.message;
    EXPECT_EQ(parser.stats().errors, 1u) << bad.message;
    EXPECT_NE(parser.last_error().find(bad.reason), std::string::npos)
        << "message " << testing::PrintToString(bad.message) << ": " << parser.last_error();
  }
  // The rejected message is quoted, control bytes escaped.
  SlcanParser parser;
  parser.feed("t1\x01\xff\r");
  EXPECT_NE(parser.last_error().find("'t1\\x01\\xFF'"), std::string::npos) << parser.last_error();
}

TEST(SlcanParser, DecodesValidFramesAmongGarbage) {
  const CanFrame first = make_frame(0x101, {1, 2, 3, 4, 5, 6, 7, 8});
  const CanFrame second = make_frame(0x1ABCDEF, {0x42}, true);
  const CanFrame third = make_remote(0x102, 8);
  const std::string stream = encode_slcan(first) + "garbage\r" + "t1232DEA\r" + "\a" +
                             "t123900112233445566778899\r" + encode_slcan(second) + "z\r" +
                             std::string("\x13\x11\x00\r", 4) + encode_slcan(third);
  SlcanParser parser;
  std::mt19937 generator(3);
  for (size_t position = 0; position < stream.size();) {
    const size_t chunk = std::min<size_t>(1 + generator() % 7, stream.size() - position);
    parser.feed(std::string_view(stream).substr(position, chunk));
    position += chunk;
  }
  EXPECT_EQ(parser.take_frames(), (std::vector<CanFrame>{first, second, third}));
  EXPECT_EQ(parser.stats().frames, 3u);
  EXPECT_EQ(parser.stats().errors, 4u);  // garbage, wrong length, DLC 9, control bytes
  EXPECT_EQ(parser.stats().bells, 1u);
  EXPECT_EQ(parser.stats().replies, 1u);
  EXPECT_EQ(parser.stats().discarded_bytes, 0u);
  EXPECT_NE(parser.last_error().find("unknown message type '\\x13'"), std::string::npos)
      << parser.last_error();
}

TEST(SlcanParser, DiscardsAnEndlessLineWithBoundedMemory) {
  SlcanParser parser;  // max_message_length 64
  const std::string endless(1000, 'A');
  size_t largest_pending = 0;
  for (char byte : endless) {
    parser.feed(std::string_view(&byte, 1));
    largest_pending = std::max(largest_pending, parser.pending_bytes());
  }
  EXPECT_EQ(largest_pending, 64u);
  EXPECT_EQ(parser.pending_bytes(), 0u);  // dropped, the rest is skipped unbuffered
  EXPECT_EQ(parser.stats().errors, 1u);   // counted once, not per byte
  EXPECT_NE(parser.last_error().find("no terminator within 64 bytes"), std::string::npos)
      << parser.last_error();

  // Its end, and the frame after it. The end of the endless line is no frame.
  parser.feed("t1232DEAD\rt4561AA\r");
  EXPECT_EQ(parser.take_frames(), (std::vector<CanFrame>{make_frame(0x456, {0xAA})}));
  EXPECT_EQ(parser.stats().discarded_bytes, 1000u + 9u);
  EXPECT_EQ(parser.stats().errors, 1u);

  // In one chunk, with a smaller limit.
  SlcanParser small({.max_message_length = 30});
  small.feed(std::string(1000, 'B') + "\r" + encode_slcan(make_frame(0x1, {})));
  EXPECT_EQ(small.take_frames(), (std::vector<CanFrame>{make_frame(0x1, {})}));
  EXPECT_EQ(small.stats().discarded_bytes, 1000u);
  EXPECT_EQ(small.stats().errors, 1u);
  // The longest valid message (extended, 8 bytes, timestamp: 30 characters) still fits.
  small.feed("T1FFFFFFF80011223344556677EA5F\r");
  EXPECT_EQ(small.take_frames().size(), 1u);
  EXPECT_EQ(small.stats().errors, 1u) << small.last_error();
}

TEST(SlcanParser, ResetDropsAnUnfinishedMessage) {
  SlcanParser parser;
  parser.feed("t1232DE");
  EXPECT_EQ(parser.pending_bytes(), 7u);
  parser.reset();
  EXPECT_EQ(parser.pending_bytes(), 0u);
  parser.feed("t4560\r");
  EXPECT_EQ(parser.take_frames(), (std::vector<CanFrame>{make_frame(0x456, {})}));
  EXPECT_EQ(parser.stats().errors, 0u);
}

// --- candump -L logs ------------------------------------------------------------------------

TEST(CandumpLine, ParsesTheFormsCandumpWrites) {
  CandumpRecord record = parse_candump_line("(1436509052.249713) can0 123#DEADBEEF");
  EXPECT_EQ(record.stamp_ns, 1436509052249713000);
  EXPECT_EQ(record.interface, "can0");
  CanFrame expected = make_frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF});
  expected.stamp_ns = 1436509052249713000;
  EXPECT_EQ(record.frame, expected);

  record = parse_candump_line("(0000000001.000001) vcan0 12345678#00");
  EXPECT_EQ(record.stamp_ns, 1000001000);
  EXPECT_EQ(record.interface, "vcan0");
  EXPECT_EQ(record.frame.id, 0x12345678u);
  EXPECT_TRUE(record.frame.extended);
  EXPECT_EQ(record.frame.length, 1);

  record = parse_candump_line("(1.5) slcan0 123#R");
  EXPECT_EQ(record.stamp_ns, 1500000000);
  EXPECT_TRUE(record.frame.remote);
  EXPECT_EQ(record.frame.length, 0);

  EXPECT_EQ(parse_candump_line("(1.0) can0 00000123#R8").frame.length, 8);
  EXPECT_TRUE(parse_candump_line("(1.0) can0 00000123#R8").frame.extended);

  record = parse_candump_line("(2.000000001) can0 7FF#");
  EXPECT_EQ(record.stamp_ns, 2000000001);
  EXPECT_EQ(record.frame.length, 0);
  EXPECT_FALSE(record.frame.remote);

  // '.' between bytes, lowercase hex, blanks and '\r' around, candump -x's direction flag.
  EXPECT_EQ(parse_candump_line("(1.0) can0 1ab#de.ad.be.ef").frame.data,
            (std::array<uint8_t, 8>{0xDE, 0xAD, 0xBE, 0xEF, 0, 0, 0, 0}));
  EXPECT_EQ(parse_candump_line("  (1.0)  can0\t123#11 R \r").frame, [] {
    CanFrame frame = make_frame(0x123, {0x11});
    frame.stamp_ns = 1000000000;
    return frame;
  }());
  EXPECT_EQ(parse_candump_line("(1.0) can0 123#11 T").interface, "can0");
}

TEST(CandumpLine, RejectsMalformedLinesWithTheReason) {
  struct Case {
    std::string line;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {"", "empty line"},
      {"can0 123#11", "does not start with '(seconds.fraction)'"},
      {"(1.0 can0 123#11", "has no ')' after the timestamp"},
      {"(abc.0) can0 123#11", "timestamp '(abc.0)' is not (seconds.fraction)"},
      {"(1.) can0 123#11", "is not (seconds.fraction)"},
      {"(-1.0) can0 123#11", "is not (seconds.fraction)"},
      {"(1.0123456789) can0 123#11", "more than 9 fraction digits"},
      {"(99999999999.0) can0 123#11", "is too large"},
      {"(1.0) can0", "lacks the interface or the frame"},
      {"(1.0) can0 12311", "has no '#' between id and data"},
      {"(1.0) can0 12#11", "must have 3 (standard) or 8 (extended) hex digits"},
      {"(1.0) can0 12G#11", "id '12G' is not hexadecimal"},
      {"(1.0) can0 800#11", "standard id 800 is above 7FF"},
      {"(1.0) can0 9FFFFFFF#11", "extended id 9FFFFFFF is above 1FFFFFFF"},
      {"(1.0) can0 2000008C#0000000000000000", "error frame '2000008C#0000000000000000'"},
      {"(1.0) can0 123##1DEADBEEF", "CAN FD frame '123##1DEADBEEF' ('##') is not supported"},
      {"(1.0) can0 123#DEA", "is not pairs of hex digits"},
      {"(1.0) can0 123#DE.A", "is not pairs of hex digits"},
      {"(1.0) can0 123#XY", "is not pairs of hex digits"},
      {"(1.0) can0 123#001122334455667788", "has more than 8 data bytes"},
      {"(1.0) can0 123#1122334455667788_9", "raw DLC suffix"},
      {"(1.0) can0 123#R9", "only a length digit 0..8 may follow the 'R'"},
      {"(1.0) can0 123#R11", "only a length digit 0..8 may follow the 'R'"},
      {"(1.0) can0 123#11 extra", "unexpected 'extra' after the frame"},
      {"(1.0) can0 123#11 R more", "unexpected 'R' after the frame"},
  };
  for (const Case& bad : cases) {
    const std::string error = error_of<CandumpError>([&] { parse_candump_line(bad.line); });
    EXPECT_NE(error.find(bad.reason), std::string::npos) << "line '" << bad.line << "': " << error;
  }
}

TEST(CandumpLine, FormatsAsCandumpDoes) {
  CandumpRecord record{1436509052249713000, "can0", make_frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF})};
  EXPECT_EQ(format_candump_line(record), "(1436509052.249713) can0 123#DEADBEEF");
  // Seconds padded to 10 digits, microseconds truncated.
  record = {1000001999, "vcan0", make_frame(0x12345678, {0}, true)};
  EXPECT_EQ(format_candump_line(record), "(0000000001.000001) vcan0 12345678#00");
  record = {0, "slcan0", make_remote(0x7FF, 0)};
  EXPECT_EQ(format_candump_line(record), "(0000000000.000000) slcan0 7FF#R");
}

TEST(CandumpLine, FormatRefusesWhatCannotBeALogLine) {
  EXPECT_THROW(format_candump_line({-1, "can0", make_frame(0x1, {})}), std::invalid_argument);
  EXPECT_THROW(format_candump_line({0, "", make_frame(0x1, {})}), std::invalid_argument);
  EXPECT_THROW(format_candump_line({0, "can 0", make_frame(0x1, {})}), std::invalid_argument);
  EXPECT_THROW(format_candump_line({0, "can0", make_frame(0x800, {})}), std::invalid_argument);
}

TEST(CandumpLine, FormatAndParseRoundTrip) {
  std::mt19937_64 generator(5);
  for (CanFrame frame : random_frames(500, 17)) {
    // Microsecond stamps: what a candump line holds.
    CandumpRecord record{static_cast<int64_t>(generator() % 4'000'000'000'000'000) * 1000, "can1",
                         frame};
    record.frame.stamp_ns = record.stamp_ns;
    const std::string line = format_candump_line(record);
    const CandumpRecord parsed = parse_candump_line(line);
    EXPECT_EQ(parsed.stamp_ns, record.stamp_ns) << line;
    EXPECT_EQ(parsed.interface, record.interface) << line;
    EXPECT_EQ(parsed.frame, record.frame) << line;
    EXPECT_EQ(format_candump_line(parsed), line);
  }
}

TEST(CandumpFile, ReadsRecordsSkippingCommentsAndBlankLines) {
  test::TempDir folder;
  const std::filesystem::path path = folder / "pixart.log";
  test::write_file(path,
                   "# recorded by the PixArt box simulator\n"
                   "\n"
                   "(1436509052.249713) can0 100#03FF03FF03FF03FF\r\n"
                   "   \n"
                   "  # an indented comment\n"
                   "(1436509052.253417) can0 101#0123004501670089\n"
                   "(1436509052.257100) can0 102#\n");  // no newline needed at the end
  const std::vector<CandumpRecord> records = read_candump_file(path.string());
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[0].stamp_ns, 1436509052249713000);
  EXPECT_EQ(to_string(records[0].frame), "100#03FF03FF03FF03FF");
  EXPECT_EQ(to_string(records[1].frame), "101#0123004501670089");
  EXPECT_EQ(records[1].frame.stamp_ns, 1436509052253417000);
  EXPECT_EQ(to_string(records[2].frame), "102#");

  CandumpReader reader(path.string());
  EXPECT_EQ(reader.line_number(), 0u);
  ASSERT_TRUE(reader.next().has_value());
  EXPECT_EQ(reader.line_number(), 3u);
  ASSERT_TRUE(reader.next().has_value());
  EXPECT_EQ(reader.line_number(), 6u);
  ASSERT_TRUE(reader.next().has_value());
  EXPECT_FALSE(reader.next().has_value());
  EXPECT_FALSE(reader.next().has_value());
}

TEST(CandumpFile, MalformedLineNamesFileAndLine) {
  test::TempDir folder;
  const std::string path = (folder / "broken.log").string();
  test::write_file(path,
                   "# header\n"
                   "(1.000000) can0 123#11\n"
                   "\n"
                   "(1.000100) can0 123##1DEAD\n"
                   "(1.000200) can0 123#11\n");
  const std::string error = error_of<CandumpError>([&] { read_candump_file(path); });
  EXPECT_EQ(error.rfind(path + ":4: ", 0), 0u) << error;
  EXPECT_NE(error.find("CAN FD"), std::string::npos) << error;

  // The reader delivers the lines before the bad one.
  CandumpReader reader(path);
  EXPECT_TRUE(reader.next().has_value());
  EXPECT_THROW(reader.next(), CandumpError);
}

TEST(CandumpFile, UnreadableFileNamesFileAndReason) {
  test::TempDir folder;
  const std::string missing = (folder / "missing.log").string();
  std::string error = error_of<CandumpError>([&] { read_candump_file(missing); });
  EXPECT_EQ(error, missing + ": cannot read the candump log: No such file or directory");

  error = error_of<CandumpError>([&] { read_candump_file(folder.path().string()); });
  EXPECT_EQ(error, folder.path().string() + ": cannot read the candump log: Is a directory");
}

// --- Serial ports over pseudo-terminals ------------------------------------------------------

TEST(SerialPort, ReceivesWhatTheMasterWrites) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path());
  EXPECT_EQ(port.device(), pty.slave_path());
  const std::string bytes = all_byte_values() + "t1232DEAD\r";
  pty.write_all(bytes);
  EXPECT_EQ(read_bytes(port, bytes.size()), bytes);
}

TEST(SerialPort, WritesReachTheMaster) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path(), {.baud_rate = 921600});
  const std::string bytes = all_byte_values() + "C\rS6\rO\r";
  port.write_all(bytes);
  EXPECT_EQ(read_bytes(pty, bytes.size()), bytes);
}

TEST(SerialPort, ReadTimesOutWithoutData) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path());
  char buffer[64];
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(port.read(buffer, sizeof(buffer), 50ms), 0u);
  EXPECT_LT(std::chrono::steady_clock::now() - start, kArrivalTimeout);
}

TEST(SerialPort, DiscardsWhatArrivedBeforeItWasOpened) {
  PseudoTerminal pty;
  pty.write_all("stale\r");
  SerialPort port(pty.slave_path());
  pty.write_all("t1230\r");
  EXPECT_EQ(read_bytes(port, 6), "t1230\r");

  PseudoTerminal keeping;
  keeping.write_all("kept\r");
  SerialPort keeper(keeping.slave_path(), {.discard_pending_input = false});
  EXPECT_EQ(read_bytes(keeper, 5), "kept\r");
}

TEST(SerialPort, ClosedMasterIsAnUnpluggedDevice) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path());
  const std::string path = pty.slave_path();
  pty.close_master();
  EXPECT_EQ(pty.master_fd(), -1);
  char buffer[64];
  const std::string error =
      error_of<SerialError>([&] { port.read(buffer, sizeof(buffer), kArrivalTimeout); });
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_NE(error.find("hung up"), std::string::npos) << error;
  EXPECT_THROW(port.write_all("t1230\r"), SerialError);

  // The device is gone: opening it again fails, naming it.
  const std::string reopen = error_of<SerialError>([&] { SerialPort again(path); });
  EXPECT_NE(reopen.find(path), std::string::npos) << reopen;
  // The master is gone too.
  EXPECT_THROW(pty.write_all("x"), SerialError);
  EXPECT_THROW(pty.read(buffer, sizeof(buffer), 10ms), SerialError);
}

TEST(SerialPort, OpenErrorsNameTheDevice) {
  const std::string missing = "/dev/mocap_no_such_serial_device";
  EXPECT_EQ(error_of<SerialError>([&] { SerialPort port(missing); }),
            "cannot open serial device " + missing + ": No such file or directory");

  test::TempDir folder;
  const std::string plain_file = (folder / "not_a_tty").string();
  test::write_file(plain_file, "");
  const std::string not_tty = error_of<SerialError>([&] { SerialPort port(plain_file); });
  EXPECT_EQ(not_tty.rfind(plain_file + " is not a serial device", 0), 0u) << not_tty;
  EXPECT_NE(not_tty.find("Inappropriate ioctl for device"), std::string::npos) << not_tty;
}

TEST(SerialPort, UnsupportedBaudRateNamesTheSupportedOnes) {
  PseudoTerminal pty;
  const std::string error = error_of<std::invalid_argument>(
      [&] { SerialPort port(pty.slave_path(), {.baud_rate = 12345}); });
  EXPECT_NE(error.find("12345"), std::string::npos) << error;
  EXPECT_NE(error.find("9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 576000, "
                       "921600, 1000000, 2000000, 3000000"),
            std::string::npos)
      << error;
  const std::vector<int> rates = supported_baud_rates();
  EXPECT_TRUE(std::is_sorted(rates.begin(), rates.end()));
  for (int rate : rates) EXPECT_NO_THROW(SerialPort(pty.slave_path(), {.baud_rate = rate})) << rate;
}

TEST(SerialPort, WriteGivesUpWhenNobodyReads) {
  PseudoTerminal pty;
  SerialPort port(pty.slave_path(), {.write_timeout = 100ms});
  const std::string megabyte(1 << 20, 'x');
  const auto start = std::chrono::steady_clock::now();
  const std::string error = error_of<SerialError>([&] { port.write_all(megabyte); });
  EXPECT_LT(std::chrono::steady_clock::now() - start, kArrivalTimeout);
  EXPECT_NE(error.find(pty.slave_path()), std::string::npos) << error;
  EXPECT_NE(error.find("of 1048576 bytes in 100 ms"), std::string::npos) << error;
}

TEST(SerialPort, MovesKeepTheDeviceOpen) {
  PseudoTerminal pty;
  SerialPort first(pty.slave_path());
  SerialPort second(std::move(first));
  EXPECT_EQ(first.fd(), -1);
  pty.write_all("abc");
  EXPECT_EQ(read_bytes(second, 3), "abc");
  PseudoTerminal moved_pty(std::move(pty));
  EXPECT_EQ(pty.master_fd(), -1);
  moved_pty.write_all("def");
  EXPECT_EQ(read_bytes(second, 3), "def");
}

TEST(PseudoTerminal, KnowsWhetherSomeoneHasTheSlaveOpen) {
  PseudoTerminal pty;
  EXPECT_FALSE(pty.peer_connected());
  {
    SerialPort port(pty.slave_path());
    EXPECT_TRUE(pty.peer_connected());
  }
  EXPECT_FALSE(pty.peer_connected());
  // Without a peer a read waits for one and then times out; it does not fail.
  char buffer[16];
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(pty.read(buffer, sizeof(buffer), 50ms), 0u);
  EXPECT_LT(std::chrono::steady_clock::now() - start, kArrivalTimeout);
  // The peer comes back (a replugged host): both ways work again.
  SerialPort port(pty.slave_path());
  EXPECT_TRUE(pty.peer_connected());
  port.write_all("O\r");
  EXPECT_EQ(read_bytes(pty, 2), "O\r");
  pty.write_all("\r");
  EXPECT_EQ(read_bytes(port, 1), "\r");
}

TEST(PseudoTerminal, WriteGivesUpWhenNobodyReads) {
  PseudoTerminal pty({.write_timeout = 100ms});
  const std::string error =
      error_of<SerialError>([&] { pty.write_all(std::string(1 << 20, 'x')); });
  EXPECT_NE(error.find(pty.slave_path()), std::string::npos) << error;
  EXPECT_NE(error.find("nobody reading?"), std::string::npos) << error;
}

// What the bridge will do with an SLCAN adaptor, against a simulated one on a pty.
TEST(SerialPort, CarriesAnSlcanSessionBothWays) {
  PseudoTerminal adaptor;
  SerialPort port(adaptor.slave_path());

  std::string commands;
  for (const std::string& command : slcan_open_commands(1000000)) {
    port.write_all(command);
    commands += command;
  }
  EXPECT_EQ(read_bytes(adaptor, commands.size()), "C\rS8\rZ1\rO\r");

  const std::vector<CanFrame> frames = random_frames(200, 23);
  const std::string stream = "\r\r\r\r" + encode_all(frames);  // the replies, then traffic
  std::mt19937 generator(29);
  for (size_t position = 0; position < stream.size();) {
    const size_t chunk = std::min<size_t>(1 + generator() % 100, stream.size() - position);
    adaptor.write_all(std::string_view(stream).substr(position, chunk));
    position += chunk;
  }
  SlcanParser parser;
  std::vector<CanFrame> decoded;
  const auto deadline = std::chrono::steady_clock::now() + kArrivalTimeout;
  char buffer[64];  // small reads: frames split across them
  while (decoded.size() < frames.size() && std::chrono::steady_clock::now() < deadline) {
    parser.feed(std::string_view(buffer, port.read(buffer, sizeof(buffer), 100ms)), 5);
    for (const CanFrame& frame : parser.take_frames()) decoded.push_back(frame);
  }
  EXPECT_EQ(decoded, with_stamp(frames, 5));
  EXPECT_EQ(parser.stats().replies, 4u);
  EXPECT_EQ(parser.stats().errors, 0u) << parser.last_error();
}

// --- SocketCAN ------------------------------------------------------------------------------

TEST(SocketCanFrames, ConvertToAndFromTheKernelsLayout) {
  struct can_frame linux_frame = to_linux_frame(make_frame(0x123, {0xDE, 0xAD}));
  EXPECT_EQ(linux_frame.can_id, 0x123u);
  EXPECT_EQ(linux_frame.len, 2);
  EXPECT_EQ(linux_frame.data[0], 0xDE);
  EXPECT_EQ(linux_frame.data[1], 0xAD);

  linux_frame = to_linux_frame(make_frame(0x12345678, {}, true));
  EXPECT_EQ(linux_frame.can_id, 0x12345678u | CAN_EFF_FLAG);
  EXPECT_EQ(linux_frame.len, 0);

  linux_frame = to_linux_frame(make_remote(0x7FF, 4));
  EXPECT_EQ(linux_frame.can_id, 0x7FFu | CAN_RTR_FLAG);
  EXPECT_EQ(linux_frame.len, 4);

  linux_frame = to_linux_frame(make_remote(0x1FFFFFFF, 8, true));
  EXPECT_EQ(linux_frame.can_id, 0x1FFFFFFFu | CAN_EFF_FLAG | CAN_RTR_FLAG);

  // From the kernel: flags leave the id; a remote frame's data bytes are not data.
  struct can_frame received {};
  received.can_id = 0x0ABCDEF | CAN_EFF_FLAG | CAN_RTR_FLAG;
  received.len = 3;
  received.data[0] = 0x55;
  EXPECT_EQ(from_linux_frame(received), make_remote(0x0ABCDEF, 3, true));

  for (const CanFrame& frame : random_frames(500, 31)) {
    EXPECT_EQ(from_linux_frame(to_linux_frame(frame)), frame);
  }
  EXPECT_THROW(to_linux_frame(make_frame(0x800, {})), std::invalid_argument);
}

// The reason SocketCAN is unusable here, or "" if `interface` opened.
std::string socketcan_unavailable_reason(const std::string& interface) {
  try {
    SocketCan probe(interface);
    return "";
  } catch (const SocketCanError& error) {
    if (error.kind() == SocketCanError::Kind::kIo) throw;
    return error.what();
  }
}

TEST(SocketCan, MissingInterfaceOrKernelSupportIsNamed) {
  const std::string interface = "mocap_nocan9";
  try {
    SocketCan can_socket(interface);
    FAIL() << "opened a CAN interface that does not exist";
  } catch (const SocketCanError& error) {
    const std::string message = error.what();
    if (error.kind() == SocketCanError::Kind::kNoKernelSupport) {
      EXPECT_EQ(message.rfind("CAN sockets are not supported by this kernel (socket(PF_CAN, "
                              "SOCK_RAW, CAN_RAW): ",
                              0),
                0u)
          << message;
      EXPECT_NE(message.find("'" + interface + "'"), std::string::npos) << message;
    } else {
      EXPECT_EQ(error.kind(), SocketCanError::Kind::kNoInterface) << message;
      EXPECT_EQ(message, "CAN interface 'mocap_nocan9' not found: No such device");
    }
  }
}

TEST(SocketCan, LiveRoundTripOnVcan0) {
  const std::string reason = socketcan_unavailable_reason("vcan0");
  if (!reason.empty()) GTEST_SKIP() << reason;

  // Two sockets: the kernel echoes a sent frame to the other sockets on the interface.
  SocketCan receiver("vcan0");
  SocketCan sender("vcan0");
  const std::vector<CanFrame> frames = {make_frame(0x123, {0xDE, 0xAD, 0xBE, 0xEF}),
                                        make_frame(0x12345678, {0x00}, true), make_remote(0x101, 0),
                                        make_frame(0x7FF, {})};
  for (const CanFrame& frame : frames) sender.write(frame);
  for (const CanFrame& expected : frames) {
    std::optional<CanFrame> received = receiver.read(kArrivalTimeout);
    ASSERT_TRUE(received.has_value()) << "frame " << to_string(expected) << " never arrived";
    EXPECT_GT(received->stamp_ns, 0);
    received->stamp_ns = 0;
    EXPECT_EQ(*received, expected);
  }
  EXPECT_FALSE(receiver.read(50ms).has_value());
}

// --- options ----------------------------------------------------------------------------------
// Options built in code get the checks a launch file's parameters get from the plugins' ranges:
// what takes them refuses them first, naming the field.

constexpr const char* kSupportedBaudRates =
    "9600, 19200, 38400, 57600, 115200, 230400, 460800, 500000, 576000, 921600, 1000000, "
    "2000000, 3000000";

TEST(SerialPortOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(serial::SerialPortOptions{}.problem(), std::nullopt);
  EXPECT_EQ(serial::SerialPortOptions{.baud_rate = 12345}.problem(),
            std::string("baud_rate: 12345 is not supported; supported: ") + kSupportedBaudRates);
  EXPECT_EQ(serial::SerialPortOptions{.write_timeout = -1ms}.problem(),
            "write_timeout: -1 ms is below 0");
  EXPECT_EQ(serial::SerialPortOptions{.write_timeout = 0ms}.problem(), std::nullopt);  // no wait
  EXPECT_EQ(serial::PseudoTerminalOptions{}.problem(), std::nullopt);
  EXPECT_EQ(serial::PseudoTerminalOptions{.write_timeout = -5ms}.problem(),
            "write_timeout: -5 ms is below 0");

  PseudoTerminal pty;
  EXPECT_EQ(error_of<std::invalid_argument>(
                [&] { SerialPort port(pty.slave_path(), {.write_timeout = -1ms}); }),
            "SerialPortOptions::write_timeout: -1 ms is below 0");
  EXPECT_EQ(error_of<std::invalid_argument>([] { PseudoTerminal other({.write_timeout = -5ms}); }),
            "PseudoTerminalOptions::write_timeout: -5 ms is below 0");
}

TEST(SlcanParserOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(SlcanParserOptions{}.problem(), std::nullopt);
  // The longest valid message (extended, 8 bytes, timestamp) must fit.
  EXPECT_EQ(SlcanParserOptions{.max_message_length = 30}.problem(), std::nullopt);
  EXPECT_EQ(SlcanParserOptions{.max_message_length = 29}.problem(),
            "max_message_length: 29; the longest valid message has 30 characters");
  EXPECT_EQ(error_of<std::invalid_argument>([] { SlcanParser parser({.max_message_length = 0}); }),
            "SlcanParserOptions::max_message_length: 0; the longest valid message has 30 "
            "characters");
}

TEST(CanSourceOptions, NameTheFieldThatCannotBeUsed) {
  // A device and a file have no default: the options without them cannot be used.
  EXPECT_EQ(SlcanSourceOptions{.device = "/dev/ttyACM0"}.problem(), std::nullopt);
  EXPECT_EQ(SlcanSourceOptions{}.problem(),
            "device: empty; the adaptor's serial device, e.g. /dev/ttyACM0");
  EXPECT_EQ((SlcanSourceOptions{.device = "/dev/ttyACM0", .bitrate = 300000}.problem()),
            "bitrate: 300000 bit/s is not an SLCAN bitrate; supported: 10000, 20000, 50000, "
            "100000, 125000, 250000, 500000, 800000, 1000000");
  EXPECT_EQ((SlcanSourceOptions{.device = "/dev/ttyACM0", .baud = 12345}.problem()),
            std::string("baud: 12345 is not supported; supported: ") + kSupportedBaudRates);
  EXPECT_EQ(CandumpSourceOptions{.file = "box.log"}.problem(), std::nullopt);
  EXPECT_EQ(CandumpSourceOptions{}.problem(), "file: empty; a `candump -L` log to read");
  // Refused before the device is looked for.
  EXPECT_EQ(error_of<std::invalid_argument>(
                [] { open_slcan({.device = "/nonexistent/tty", .bitrate = 300000}); }),
            "SlcanSourceOptions::bitrate: 300000 bit/s is not an SLCAN bitrate; supported: 10000, "
            "20000, 50000, 100000, 125000, 250000, 500000, 800000, 1000000");
  EXPECT_EQ(error_of<std::invalid_argument>([] { open_candump({}); }),
            "CandumpSourceOptions::file: empty; a `candump -L` log to read");
}

}  // namespace
}  // namespace mocap::can
