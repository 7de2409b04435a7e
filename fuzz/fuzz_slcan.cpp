// SLCAN from a serial line, where anything may come (another device, a wrong baud rate): the
// parser counts what it rejects and never throws, its buffer stays within max_message_length,
// and how the bytes are split into reads changes nothing. What it yields can go on a bus and
// comes back through encode_slcan as the same frame.
#include <cstdint>
#include <cstdlib>
#include <string_view>
#include <vector>

#include "common/can_io/can_frame.hpp"
#include "common/can_io/slcan.hpp"

namespace {

bool same_stats(const mocap::can::SlcanStats& a, const mocap::can::SlcanStats& b) {
  return a.frames == b.frames && a.errors == b.errors && a.bells == b.bells &&
         a.replies == b.replies && a.discarded_bytes == b.discarded_bytes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using mocap::can::CanFrame;
  using mocap::can::SlcanParser;
  if (size < 1) return 0;
  // The first byte is the size of the reads, the rest what the adaptor sent.
  const size_t read_size = 1 + data[0];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  constexpr int64_t kStamp = 1'700'000'000'000'000'000;

  SlcanParser reads;
  std::vector<CanFrame> frames;
  for (size_t offset = 0; offset < bytes.size(); offset += read_size) {
    reads.feed(bytes.substr(offset, read_size), kStamp);
    if (reads.pending_bytes() > mocap::can::SlcanParserOptions{}.max_message_length) std::abort();
    for (const CanFrame& frame : reads.take_frames()) frames.push_back(frame);
  }
  SlcanParser at_once;
  at_once.feed(bytes, kStamp);
  if (at_once.take_frames() != frames || !same_stats(at_once.stats(), reads.stats())) std::abort();
  if (reads.stats().frames != frames.size()) std::abort();

  for (const CanFrame& frame : frames) {
    mocap::can::validate_frame(frame);  // std::invalid_argument escapes: a crash
    SlcanParser again;
    again.feed(mocap::can::encode_slcan(frame), kStamp);
    const std::vector<CanFrame> back = again.take_frames();
    if (back.size() != 1 || back[0] != frame || again.stats().errors != 0) std::abort();
  }
  return 0;
}
