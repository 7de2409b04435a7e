#include "tracking/camera_source/v4l2_capture.hpp"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/core.hpp>

namespace mocap::capture {
namespace {

class SystemV4l2Io final : public V4l2Io {
 public:
  int open(const char* path, int flags) override { return ::open(path, flags); }
  int close(int fd) override { return ::close(fd); }
  int ioctl(int fd, unsigned long request, void* argument) override {
    int result;
    do {
      result = ::ioctl(fd, request, argument);
    } while (result == -1 && errno == EINTR);
    return result;
  }
  void* mmap(size_t length, int fd, off_t offset) override {
    return ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, offset);
  }
  int munmap(void* address, size_t length) override { return ::munmap(address, length); }
  int poll(int fd, int timeout_ms) override {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms);
  }
  std::chrono::nanoseconds monotonic_now() override {
    timespec t{};
    clock_gettime(CLOCK_MONOTONIC, &t);
    return std::chrono::seconds(t.tv_sec) + std::chrono::nanoseconds(t.tv_nsec);
  }
  std::chrono::system_clock::time_point system_now() override {
    return std::chrono::system_clock::now();
  }
};

std::string fourcc(uint32_t format) {
  std::string text(4, ' ');
  for (int i = 0; i < 4; ++i) text[static_cast<size_t>(i)] = static_cast<char>(format >> (8 * i));
  return text;
}

}  // namespace

std::unique_ptr<V4l2Io> system_v4l2_io() { return std::make_unique<SystemV4l2Io>(); }

V4l2Capture::V4l2Capture(std::string device, const V4l2Options& options, std::unique_ptr<V4l2Io> io)
    : device_(std::move(device)), io_(std::move(io)), timeout_(options.timeout) {
  if (options.width < 0 || options.height < 0 || options.buffers < 2) {
    throw std::invalid_argument(
        fmt::format("{}: width {} and height {} must be 0 or more, buffers {} at least 2", device_,
                    options.width, options.height, options.buffers));
  }
  fd_ = io_->open(device_.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) fail(fmt::format("cannot open: {}", std::strerror(errno)));
  try {
    v4l2_capability capability{};
    xioctl(VIDIOC_QUERYCAP, &capability, "VIDIOC_QUERYCAP");
    const uint32_t caps = (capability.capabilities & V4L2_CAP_DEVICE_CAPS) != 0
                              ? capability.device_caps
                              : capability.capabilities;
    if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0) fail("not a video capture device");
    if ((caps & V4L2_CAP_STREAMING) == 0) fail("does not stream (no memory-mapped buffers)");

    v4l2_format format{};
    format.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    xioctl(VIDIOC_G_FMT, &format, "VIDIOC_G_FMT");
    if (options.width > 0) format.fmt.pix.width = static_cast<uint32_t>(options.width);
    if (options.height > 0) format.fmt.pix.height = static_cast<uint32_t>(options.height);
    xioctl(VIDIOC_S_FMT, &format, "VIDIOC_S_FMT");
    format_ = format.fmt.pix.pixelformat;
    if (format_ != V4L2_PIX_FMT_GREY && format_ != V4L2_PIX_FMT_Y16 &&
        format_ != V4L2_PIX_FMT_YUYV) {
      fail(fmt::format("pixel format {} is not read: GREY, Y16 or YUYV", fourcc(format_)));
    }
    width_ = static_cast<int>(format.fmt.pix.width);
    height_ = static_cast<int>(format.fmt.pix.height);
    const uint32_t bytes_per_pixel = format_ == V4L2_PIX_FMT_GREY ? 1 : 2;
    bytes_per_line_ = std::max(format.fmt.pix.bytesperline, format.fmt.pix.width * bytes_per_pixel);

    v4l2_control exposure{};
    exposure.id = V4L2_CID_EXPOSURE_ABSOLUTE;
    if (io_->ioctl(fd_, VIDIOC_G_CTRL, &exposure) == 0 && exposure.value > 0) {
      exposure_ = std::chrono::microseconds(int64_t{exposure.value} * 100);  // in 100 us
    }

    v4l2_requestbuffers request{};
    request.count = static_cast<uint32_t>(options.buffers);
    request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    request.memory = V4L2_MEMORY_MMAP;
    xioctl(VIDIOC_REQBUFS, &request, "VIDIOC_REQBUFS");
    if (request.count < 2)
      fail(fmt::format("the driver gave {} buffer(s), 2 needed", request.count));
    for (uint32_t i = 0; i < request.count; ++i) {
      v4l2_buffer buffer{};
      buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      buffer.memory = V4L2_MEMORY_MMAP;
      buffer.index = i;
      xioctl(VIDIOC_QUERYBUF, &buffer, "VIDIOC_QUERYBUF");
      void* start = io_->mmap(buffer.length, fd_, static_cast<off_t>(buffer.m.offset));
      if (start == MAP_FAILED)
        fail(fmt::format("cannot map buffer {}: {}", i, std::strerror(errno)));
      buffers_.push_back({start, buffer.length});
      xioctl(VIDIOC_QBUF, &buffer, "VIDIOC_QBUF");
    }
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    xioctl(VIDIOC_STREAMON, &type, "VIDIOC_STREAMON");
    streaming_ = true;
  } catch (...) {
    for (const Buffer& buffer : buffers_) io_->munmap(buffer.start, buffer.length);
    io_->close(fd_);
    throw;
  }
}

V4l2Capture::~V4l2Capture() {
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    io_->ioctl(fd_, VIDIOC_STREAMOFF, &type);
  }
  for (const Buffer& buffer : buffers_) io_->munmap(buffer.start, buffer.length);
  io_->close(fd_);
}

void V4l2Capture::fail(const std::string& what) const {
  throw std::runtime_error(fmt::format("{}: {}", device_, what));
}

void V4l2Capture::xioctl(unsigned long request, void* argument, const char* name) {
  if (io_->ioctl(fd_, request, argument) != 0) {
    fail(fmt::format("{} failed: {}", name, std::strerror(errno)));
  }
}

std::string V4l2Capture::pixel_format() const { return fourcc(format_); }

// The monotonic clock and the system clock read as close together as they can be: the
// system time at `monotonic` is the one read between two monotonic readings, at their middle.
std::chrono::system_clock::time_point V4l2Capture::to_system(std::chrono::nanoseconds monotonic) {
  const std::chrono::nanoseconds before = io_->monotonic_now();
  const std::chrono::system_clock::time_point system = io_->system_now();
  const std::chrono::nanoseconds after = io_->monotonic_now();
  const std::chrono::nanoseconds now = before + (after - before) / 2;
  return system - std::chrono::duration_cast<std::chrono::system_clock::duration>(now - monotonic);
}

std::optional<V4l2Frame> V4l2Capture::read(cv::Mat& mono8) {
  const int ready = io_->poll(fd_, static_cast<int>(timeout_.count()));
  if (ready < 0 && errno != EINTR) fail(fmt::format("poll failed: {}", std::strerror(errno)));
  if (ready == 0)
    fail(fmt::format("no frame for {} ms: is the camera still there?", timeout_.count()));
  v4l2_buffer buffer{};
  buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buffer.memory = V4L2_MEMORY_MMAP;
  if (io_->ioctl(fd_, VIDIOC_DQBUF, &buffer) != 0) {
    if (errno == EAGAIN || errno == EINTR) return std::nullopt;  // woken without a frame
    fail(fmt::format("VIDIOC_DQBUF failed: {}", std::strerror(errno)));
  }
  if (buffer.index >= buffers_.size())
    fail(fmt::format("the driver returned buffer {}", buffer.index));
  const Buffer& mapped = buffers_[buffer.index];
  const size_t needed = static_cast<size_t>(bytes_per_line_) * static_cast<size_t>(height_);
  if (buffer.bytesused < needed || mapped.length < needed) {
    xioctl(VIDIOC_QBUF, &buffer, "VIDIOC_QBUF");
    fail(fmt::format("a frame of {} bytes, {} expected ({}x{} {})", buffer.bytesused, needed,
                     width_, height_, pixel_format()));
  }
  const cv::Mat raw(height_, width_,
                    format_ == V4L2_PIX_FMT_GREY  ? CV_8UC1
                    : format_ == V4L2_PIX_FMT_Y16 ? CV_16UC1
                                                  : CV_8UC2,
                    mapped.start, bytes_per_line_);
  if (format_ == V4L2_PIX_FMT_GREY) {
    raw.copyTo(mono8);
  } else if (format_ == V4L2_PIX_FMT_Y16) {
    raw.convertTo(mono8, CV_8U, 1.0 / 256);
  } else {
    mono8.create(height_, width_, CV_8UC1);
    cv::extractChannel(raw, mono8, 0);  // YUYV: Y in the first byte of each pair
  }
  V4l2Frame frame;
  frame.sequence = buffer.sequence;
  if (last_sequence_ && buffer.sequence > *last_sequence_ + 1) {
    dropped_ += buffer.sequence - *last_sequence_ - 1;
  }
  last_sequence_ = buffer.sequence;
  if ((buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) {
    const auto stamp = std::chrono::seconds(buffer.timestamp.tv_sec) +
                       std::chrono::microseconds(buffer.timestamp.tv_usec);
    const bool start_of_exposure =
        (buffer.flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) == V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
    frame.captured = to_system(stamp);
    frame.stamp_source = start_of_exposure ? "start of exposure" : "end of frame";
    if (exposure_) {
      // Half an exposure after its start, or before the frame's end (its readout taken as
      // short against the exposure, which a global-shutter IR camera's is).
      frame.captured += start_of_exposure ? *exposure_ / 2 : -*exposure_ / 2;
      frame.stamp_source = "mid-exposure";
    }
  } else {
    // A driver that stamps with no clock of its own (a copy of the writer's, or none).
    frame.captured = io_->system_now();
    frame.stamp_source = "read";
  }
  xioctl(VIDIOC_QBUF, &buffer, "VIDIOC_QBUF");
  return frame;
}

}  // namespace mocap::capture
