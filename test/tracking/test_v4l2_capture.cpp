// The V4L2 capture (v4l2_capture.hpp) against a camera that exists only as a driver's answers:
// its capabilities, its format, its memory-mapped buffers and frames recorded as a driver
// hands them out (pixels, sequence number, timestamp, flags), behind the ioctl seam. The
// capture's own code runs as it does against /dev/video0: the same requests, in the same
// order, on the same structures of <linux/videodev2.h>.
#include <gtest/gtest.h>

#include <linux/videodev2.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <map>

#include "tracking/camera_source/camera_source.hpp"
#include "tracking/camera_source/v4l2_capture.hpp"

namespace mocap::capture {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::nanoseconds;
using SystemTime = std::chrono::system_clock::time_point;

// The graph's clock and the monotonic clock as the fake reads them: fixed, so that the
// conversion is exact. Monotonic 1000 s is system 1.8e9 s.
const nanoseconds kMonotonicNow = std::chrono::seconds(1000);
const SystemTime kSystemNow{std::chrono::seconds(1'800'000'000)};

struct RecordedFrame {
  std::vector<uint8_t> bytes;  // as the driver wrote them into its buffer
  uint32_t sequence = 0;
  nanoseconds stamp{0};  // on the monotonic clock
  uint32_t flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_EOF;
};

class RecordedCamera final : public V4l2Io {
 public:
  struct State {
    uint32_t capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
    uint32_t pixel_format = V4L2_PIX_FMT_GREY;
    uint32_t width = 8, height = 4, bytes_per_line = 8;
    std::optional<int> exposure_100us;
    std::deque<RecordedFrame> frames;
    std::vector<std::string> requests;  // every ioctl's name, in order
    bool streaming = false;
    int closed = 0;
    int unmapped = 0;
  };

  explicit RecordedCamera(State& state) : s_(state) {}

  int open(const char* path, int) override {
    if (std::string(path) != "/dev/video0") {
      errno = ENOENT;
      return -1;
    }
    return 7;
  }
  int close(int) override { return ++s_.closed, 0; }
  void* mmap(size_t length, int, off_t offset) override {
    auto& buffer = buffers_.at(static_cast<size_t>(offset / 4096));
    return length == buffer.size() ? buffer.data() : MAP_FAILED;
  }
  int munmap(void*, size_t) override { return ++s_.unmapped, 0; }
  int poll(int, int) override { return s_.frames.empty() ? 0 : 1; }
  nanoseconds monotonic_now() override { return kMonotonicNow; }
  SystemTime system_now() override { return kSystemNow; }

  int ioctl(int, unsigned long request, void* argument) override {
    switch (request) {
      case VIDIOC_QUERYCAP: {
        s_.requests.push_back("QUERYCAP");
        auto* c = static_cast<v4l2_capability*>(argument);
        c->capabilities = s_.capabilities | V4L2_CAP_DEVICE_CAPS;
        c->device_caps = s_.capabilities;
        return 0;
      }
      case VIDIOC_G_FMT:
      case VIDIOC_S_FMT: {
        s_.requests.push_back(request == VIDIOC_G_FMT ? "G_FMT" : "S_FMT");
        auto* f = static_cast<v4l2_format*>(argument);
        if (request == VIDIOC_S_FMT) {  // a sensor of 8 x 4 at most
          s_.width = std::min(f->fmt.pix.width, 8u);
          s_.height = std::min(f->fmt.pix.height, 4u);
        }
        f->fmt.pix.width = s_.width;
        f->fmt.pix.height = s_.height;
        f->fmt.pix.pixelformat = s_.pixel_format;
        f->fmt.pix.bytesperline = s_.bytes_per_line;
        return 0;
      }
      case VIDIOC_G_CTRL: {
        auto* control = static_cast<v4l2_control*>(argument);
        if (control->id != V4L2_CID_EXPOSURE_ABSOLUTE || !s_.exposure_100us) {
          errno = EINVAL;
          return -1;
        }
        control->value = *s_.exposure_100us;
        return 0;
      }
      case VIDIOC_REQBUFS: {
        s_.requests.push_back("REQBUFS");
        auto* r = static_cast<v4l2_requestbuffers*>(argument);
        r->count = std::min(r->count, 3u);
        buffers_.assign(r->count, std::vector<uint8_t>(s_.bytes_per_line * s_.height));
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(argument);
        b->length = static_cast<uint32_t>(buffers_.at(b->index).size());
        b->m.offset = b->index * 4096;
        return 0;
      }
      case VIDIOC_QBUF:
        queued_.push_back(static_cast<v4l2_buffer*>(argument)->index);
        return 0;
      case VIDIOC_STREAMON:
      case VIDIOC_STREAMOFF:
        s_.requests.push_back(request == VIDIOC_STREAMON ? "STREAMON" : "STREAMOFF");
        s_.streaming = request == VIDIOC_STREAMON;
        return 0;
      case VIDIOC_DQBUF: {
        if (s_.frames.empty() || queued_.empty()) {
          errno = EAGAIN;
          return -1;
        }
        RecordedFrame frame = std::move(s_.frames.front());
        s_.frames.pop_front();
        auto* b = static_cast<v4l2_buffer*>(argument);
        b->index = queued_.front();
        queued_.pop_front();
        std::vector<uint8_t>& buffer = buffers_[b->index];
        std::copy(frame.bytes.begin(), frame.bytes.end(), buffer.begin());
        b->bytesused = static_cast<uint32_t>(frame.bytes.size());
        b->sequence = frame.sequence;
        b->flags = frame.flags;
        b->timestamp.tv_sec = frame.stamp.count() / 1'000'000'000;
        b->timestamp.tv_usec = (frame.stamp.count() % 1'000'000'000) / 1000;
        return 0;
      }
    }
    errno = ENOTTY;
    return -1;
  }

 private:
  State& s_;
  std::vector<std::vector<uint8_t>> buffers_;
  std::deque<uint32_t> queued_;
};

std::unique_ptr<V4l2Io> camera(RecordedCamera::State& state) {
  return std::make_unique<RecordedCamera>(state);
}

// An 8 x 4 GREY frame whose pixel i is `first` + i.
RecordedFrame grey_frame(uint32_t sequence, nanoseconds stamp, uint8_t first = 0) {
  RecordedFrame frame{std::vector<uint8_t>(32), sequence, stamp};
  for (size_t i = 0; i < frame.bytes.size(); ++i) frame.bytes[i] = static_cast<uint8_t>(first + i);
  return frame;
}

std::string error_of(RecordedCamera::State& state, const std::string& device = "/dev/video0") {
  try {
    V4l2Capture capture(device, {}, camera(state));
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(V4l2Capture, StreamsFromMappedBuffersAndStampsWithTheDriversTimeOnTheSystemClock) {
  RecordedCamera::State state;
  // End of frame 10 ms and 5 ms before now, on the monotonic clock.
  state.frames.push_back(grey_frame(40, kMonotonicNow - milliseconds(10), 1));
  state.frames.push_back(grey_frame(41, kMonotonicNow - milliseconds(5), 2));
  {
    V4l2Capture capture("/dev/video0", {.width = 640, .height = 480}, camera(state));
    EXPECT_EQ(capture.width(), 8);  // the driver chose its own size
    EXPECT_EQ(capture.height(), 4);
    EXPECT_EQ(capture.pixel_format(), "GREY");
    EXPECT_TRUE(state.streaming);
    cv::Mat mono8;
    auto frame = capture.read(mono8);
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->captured, kSystemNow - milliseconds(10));
    EXPECT_EQ(frame->stamp_source, "end of frame");
    EXPECT_EQ(frame->sequence, 40u);
    ASSERT_EQ(mono8.type(), CV_8UC1);
    EXPECT_EQ(mono8.cols, 8);
    EXPECT_EQ(mono8.at<uint8_t>(0, 0), 1);
    EXPECT_EQ(mono8.at<uint8_t>(3, 7), 32);
    frame = capture.read(mono8);
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->captured, kSystemNow - milliseconds(5));
    EXPECT_EQ(mono8.at<uint8_t>(0, 0), 2);
    EXPECT_EQ(capture.dropped(), 0u);
  }
  const std::vector<std::string> expected = {"QUERYCAP", "G_FMT",    "S_FMT",
                                             "REQBUFS",  "STREAMON", "STREAMOFF"};
  EXPECT_EQ(state.requests, expected);
  EXPECT_EQ(state.unmapped, 3);
  EXPECT_EQ(state.closed, 1);
}

// With the exposure known (V4L2_CID_EXPOSURE_ABSOLUTE, in 100 us), the stamp is mid-exposure:
// half of it after a start-of-exposure stamp, before an end-of-frame one.
TEST(V4l2Capture, StampsMidExposureWhereTheExposureIsKnown) {
  RecordedCamera::State state;
  state.exposure_100us = 50;  // 5 ms
  RecordedFrame start = grey_frame(1, kMonotonicNow - milliseconds(20));
  start.flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
  state.frames.push_back(start);
  state.frames.push_back(grey_frame(2, kMonotonicNow - milliseconds(10)));
  V4l2Capture capture("/dev/video0", {}, camera(state));
  ASSERT_EQ(capture.exposure(), microseconds(5000));
  cv::Mat mono8;
  auto frame = capture.read(mono8);
  EXPECT_EQ(frame->captured, kSystemNow - milliseconds(20) + microseconds(2500));
  EXPECT_EQ(frame->stamp_source, "mid-exposure");
  frame = capture.read(mono8);
  EXPECT_EQ(frame->captured, kSystemNow - milliseconds(10) - microseconds(2500));
}

TEST(V4l2Capture, ADriverWithoutAMonotonicStampIsStampedWhenRead) {
  RecordedCamera::State state;
  RecordedFrame copied = grey_frame(1, nanoseconds(123));
  copied.flags = V4L2_BUF_FLAG_TIMESTAMP_COPY;
  state.frames.push_back(copied);
  V4l2Capture capture("/dev/video0", {}, camera(state));
  cv::Mat mono8;
  auto frame = capture.read(mono8);
  EXPECT_EQ(frame->captured, kSystemNow);
  EXPECT_EQ(frame->stamp_source, "read");
}

TEST(V4l2Capture, CountsTheFramesTheDriverDropped) {
  RecordedCamera::State state;
  for (uint32_t sequence : {10u, 11u, 14u, 15u, 20u}) {
    state.frames.push_back(grey_frame(sequence, kMonotonicNow));
  }
  V4l2Capture capture("/dev/video0", {}, camera(state));
  cv::Mat mono8;
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(capture.read(mono8));
  EXPECT_EQ(capture.dropped(), 6u);  // 12, 13 and 16 to 19
}

// 16-bit grey keeps its upper byte; YUYV its luma; a padded line (bytesperline beyond the
// width) is read by its stride.
TEST(V4l2Capture, ReadsY16YuyvAndPaddedLinesAsMono8) {
  RecordedCamera::State y16;
  y16.pixel_format = V4L2_PIX_FMT_Y16;
  y16.bytes_per_line = 16;
  RecordedFrame wide{std::vector<uint8_t>(64), 1, kMonotonicNow};
  for (size_t i = 0; i < 32; ++i) {
    const uint16_t value = static_cast<uint16_t>((i << 8) | 0x7f);
    wide.bytes[2 * i] = static_cast<uint8_t>(value & 0xff);  // little-endian
    wide.bytes[2 * i + 1] = static_cast<uint8_t>(value >> 8);
  }
  y16.frames.push_back(wide);
  cv::Mat mono8;
  {
    V4l2Capture capture("/dev/video0", {}, camera(y16));
    ASSERT_TRUE(capture.read(mono8));
    EXPECT_EQ(mono8.at<uint8_t>(0, 1), 1);
    EXPECT_EQ(mono8.at<uint8_t>(3, 7), 31);
  }
  RecordedCamera::State yuyv;
  yuyv.pixel_format = V4L2_PIX_FMT_YUYV;
  yuyv.bytes_per_line = 16;
  RecordedFrame pairs{std::vector<uint8_t>(64, 0x80), 1, kMonotonicNow};
  for (size_t i = 0; i < 32; ++i) pairs.bytes[2 * i] = static_cast<uint8_t>(100 + i);
  yuyv.frames.push_back(pairs);
  {
    V4l2Capture capture("/dev/video0", {}, camera(yuyv));
    ASSERT_TRUE(capture.read(mono8));
    EXPECT_EQ(mono8.at<uint8_t>(0, 0), 100);
    EXPECT_EQ(mono8.at<uint8_t>(2, 5), 100 + 21);
  }
  RecordedCamera::State padded;
  padded.bytes_per_line = 12;
  RecordedFrame lines{std::vector<uint8_t>(48, 0xee), 1, kMonotonicNow};
  for (size_t row = 0; row < 4; ++row) {
    for (size_t col = 0; col < 8; ++col)
      lines.bytes[row * 12 + col] = static_cast<uint8_t>(row * 8 + col);
  }
  padded.frames.push_back(lines);
  V4l2Capture capture("/dev/video0", {}, camera(padded));
  ASSERT_TRUE(capture.read(mono8));
  EXPECT_EQ(mono8.at<uint8_t>(1, 0), 8);
  EXPECT_EQ(mono8.at<uint8_t>(3, 7), 31);
}

TEST(V4l2Capture, RefusesWhatItCannotReadNamingTheDevice) {
  RecordedCamera::State missing;
  EXPECT_EQ(error_of(missing, "/dev/video3"),
            "/dev/video3: cannot open: No such file or directory");
  RecordedCamera::State output;
  output.capabilities = V4L2_CAP_VIDEO_OUTPUT | V4L2_CAP_STREAMING;
  EXPECT_EQ(error_of(output), "/dev/video0: not a video capture device");
  EXPECT_EQ(output.closed, 1);
  RecordedCamera::State read_only;
  read_only.capabilities = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_READWRITE;
  EXPECT_EQ(error_of(read_only), "/dev/video0: does not stream (no memory-mapped buffers)");
  RecordedCamera::State mjpeg;
  mjpeg.pixel_format = V4L2_PIX_FMT_MJPEG;
  EXPECT_EQ(error_of(mjpeg), "/dev/video0: pixel format MJPG is not read: GREY, Y16 or YUYV");
  // A frame shorter than its format, and a camera that sends nothing: errors, not a crash.
  RecordedCamera::State short_frame;
  short_frame.frames.push_back({std::vector<uint8_t>(10), 1, kMonotonicNow});
  V4l2Capture capture("/dev/video0", {.timeout = milliseconds(50)}, camera(short_frame));
  cv::Mat mono8;
  try {
    capture.read(mono8);
    ADD_FAILURE() << "a short frame was read";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "/dev/video0: a frame of 10 bytes, 32 expected (8x4 GREY)");
  }
  try {
    capture.read(mono8);
    ADD_FAILURE() << "a frame came from nowhere";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "/dev/video0: no frame for 50 ms: is the camera still there?");
  }
}

// camera_source's device input: the frames with the driver's capture time and drops.
TEST(V4l2Capture, TheDeviceSourceGivesEachFramesCaptureTimeAndTheDrops) {
  RecordedCamera::State state;
  state.frames.push_back(grey_frame(5, kMonotonicNow - milliseconds(3)));
  state.frames.push_back(grey_frame(8, kMonotonicNow - milliseconds(1)));
  VideoDeviceSource source("0", {}, camera(state));
  EXPECT_EQ(source.description(), "device /dev/video0 (8x4 GREY, stamped as the driver does)");
  cv::Mat mono8;
  ASSERT_TRUE(source.read(mono8));
  EXPECT_EQ(source.captured(), kSystemNow - milliseconds(3));
  ASSERT_TRUE(source.read(mono8));
  EXPECT_EQ(source.captured(), kSystemNow - milliseconds(1));
  EXPECT_EQ(source.dropped(), 2u);
  EXPECT_EQ(source.frames_read(), 2u);
}

}  // namespace
}  // namespace mocap::capture
