// A V4L2 camera read directly, through memory-mapped buffers (the kernel's Video for Linux 2
// API: VIDIOC_REQBUFS, QBUF, DQBUF), so that each frame carries what the driver knows of it:
// its timestamp (taken on the monotonic clock at the start of exposure or at the end of the
// frame, as the buffer's flags say) and its sequence number, whose gaps are frames the driver
// dropped. OpenCV's VideoCapture gives neither.
//
// Every call into the kernel goes through V4l2Io, so that tests feed the capture recorded
// buffers through the same code a camera takes (no camera is needed to test it).
//
//   V4l2Capture camera("/dev/video0", {.width = 1280, .height = 720});
//   cv::Mat mono8;
//   while (auto frame = camera.read(mono8)) publish(mono8, frame->captured);
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace mocap::capture {

// The system calls a capture makes, as the kernel offers them.
class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  virtual int open(const char* path, int flags) = 0;
  virtual int close(int fd) = 0;
  // Returns -1 and sets errno on failure, as ioctl(2).
  virtual int ioctl(int fd, unsigned long request, void* argument) = 0;
  virtual void* mmap(size_t length, int fd, off_t offset) = 0;  // MAP_FAILED on failure
  virtual int munmap(void* address, size_t length) = 0;
  // Waits up to `timeout_ms` for a frame: >0 ready, 0 timed out, <0 failed (errno).
  virtual int poll(int fd, int timeout_ms) = 0;
  // The clocks, read together, to turn the driver's monotonic stamps into the graph's.
  virtual std::chrono::nanoseconds monotonic_now() = 0;
  virtual std::chrono::system_clock::time_point system_now() = 0;
};

// The kernel's.
std::unique_ptr<V4l2Io> system_v4l2_io();

struct V4l2Options {
  // Requested frame size; 0 leaves the device's. The driver may choose another: read the frames.
  int width = 0;
  int height = 0;
  // Buffers the driver fills in turn: enough to ride out a late reader without dropping.
  int buffers = 4;
  // How long read() waits for a frame before it says the camera stopped.
  std::chrono::milliseconds timeout{2000};
};

// What the driver said of one frame.
struct V4l2Frame {
  // The capture time on the system clock: mid-exposure where the exposure time is known, else
  // the driver's moment (start of exposure or end of frame, `stamp_source`).
  std::chrono::system_clock::time_point captured;
  uint32_t sequence = 0;
  std::string stamp_source;  // "mid-exposure", "start of exposure", "end of frame", "read"
};

// Pixel formats read: GREY (8-bit), Y16 (16-bit, its upper byte kept), YUYV (its luma).
class V4l2Capture {
 public:
  // Opens `device`, sets its format and starts streaming. Throws std::runtime_error naming the
  // device and what failed ("/dev/video0: not a video capture device"; "/dev/video0: pixel
  // format MJPG is not read: GREY, Y16 or YUYV").
  V4l2Capture(std::string device, const V4l2Options& options = {},
              std::unique_ptr<V4l2Io> io = system_v4l2_io());
  ~V4l2Capture();  // stops streaming, unmaps, closes
  V4l2Capture(const V4l2Capture&) = delete;
  V4l2Capture& operator=(const V4l2Capture&) = delete;

  // The next frame as mono8 into `mono8`, with what the driver said of it. Throws
  // std::runtime_error naming the device when it fails or sends nothing for `timeout`.
  std::optional<V4l2Frame> read(cv::Mat& mono8);

  int width() const { return width_; }
  int height() const { return height_; }
  std::string pixel_format() const;  // "GREY", "Y16 ", "YUYV"
  // Frames the driver dropped: gaps in the sequence numbers.
  uint64_t dropped() const { return dropped_; }
  // The exposure time from V4L2_CID_EXPOSURE_ABSOLUTE; nullopt when the driver has none.
  std::optional<std::chrono::microseconds> exposure() const { return exposure_; }

 private:
  struct Buffer {
    void* start = nullptr;
    size_t length = 0;
  };

  [[noreturn]] void fail(const std::string& what) const;
  void xioctl(unsigned long request, void* argument, const char* name);
  std::chrono::system_clock::time_point to_system(std::chrono::nanoseconds monotonic);

  std::string device_;
  std::unique_ptr<V4l2Io> io_;
  int fd_ = -1;
  std::vector<Buffer> buffers_;
  bool streaming_ = false;
  std::chrono::milliseconds timeout_;
  int width_ = 0, height_ = 0;
  uint32_t bytes_per_line_ = 0;
  uint32_t format_ = 0;
  std::optional<std::chrono::microseconds> exposure_;
  std::optional<uint32_t> last_sequence_;
  uint64_t dropped_ = 0;
};

}  // namespace mocap::capture
