// Where camera frames come from: a V4L2 device (read directly: v4l2_capture.hpp), a video file
// or a directory of images (through OpenCV), each delivered as mono8 (the one layout the image
// components read, image_message.hpp).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/videoio.hpp>

#include "tracking/camera_source/v4l2_capture.hpp"

namespace mocap::capture {

// Writes `frame` as mono8 (CV_8UC1) into `mono8`, reusing its buffer when the size fits:
// 8-bit grey is copied; BGR and BGRA become grey (cv::cvtColor); 16-bit keeps its upper byte
// (x 1/256); floating point is taken as 0..1. Throws std::invalid_argument for other layouts
// (2 channels, signed integers).
void to_mono8(const cv::Mat& frame, cv::Mat& mono8);

// A stream of frames. Not thread-safe: one reader at a time.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // The next frame as CV_8UC1 into `mono8`; false at the end of the input (never for a
  // device that keeps delivering). May block until the frame exists (devices).
  virtual bool read(cv::Mat& mono8) = 0;
  // "device /dev/video0", "file clip.avi", "directory frames/ (120 images)".
  virtual std::string description() const = 0;
  // True for a camera that paces itself; false for recorded input, which the caller paces.
  virtual bool is_live() const = 0;
  // Frames delivered so far (counting every pass of a loop).
  uint64_t frames_read() const { return frames_read_; }
  // When the last frame read was captured, as its device says (system clock); nullopt when the
  // source does not know (recorded input: the reader stamps it).
  virtual std::optional<std::chrono::system_clock::time_point> captured() const {
    return std::nullopt;
  }
  // Frames the device dropped before they could be read (its sequence's gaps).
  virtual uint64_t dropped() const { return 0; }

 protected:
  uint64_t frames_read_ = 0;
};

struct VideoDeviceOptions {
  // Requested frame size; 0 leaves the device's own. A device may pick another size: read
  // the frames' size, not this.
  int width = 0;
  int height = 0;

  // Why these options cannot be used, naming the field ("width: -1 is below 0"); nullopt when
  // they can. VideoDeviceSource's constructor throws std::invalid_argument with it.
  std::optional<std::string> problem() const;
};

// A V4L2 camera read directly (v4l2_capture.hpp): `device` is a path ("/dev/video0") or an
// index ("0": /dev/video0). Each frame is stamped with the driver's capture time and the
// driver's dropped frames are counted. Throws std::invalid_argument for options that cannot be
// used, std::runtime_error naming the device when it cannot be opened or read. `io`: the
// kernel's, or a test's recorded buffers.
class VideoDeviceSource final : public FrameSource {
 public:
  explicit VideoDeviceSource(const std::string& device, const VideoDeviceOptions& options = {},
                             std::unique_ptr<V4l2Io> io = system_v4l2_io());
  bool read(cv::Mat& mono8) override;
  std::string description() const override;
  bool is_live() const override { return true; }
  std::optional<std::chrono::system_clock::time_point> captured() const override;
  uint64_t dropped() const override { return capture_.dropped(); }

 private:
  std::string device_;
  V4l2Capture capture_;
  std::optional<V4l2Frame> last_;
};

// A video file through cv::VideoCapture: what OpenCV's FFmpeg backend decodes, or its own
// MJPEG reader. `loop`: start over at the end. Throws std::runtime_error naming the file when
// it does not exist or cannot be decoded.
class VideoFileSource final : public FrameSource {
 public:
  explicit VideoFileSource(std::filesystem::path path, bool loop = false);
  bool read(cv::Mat& mono8) override;
  std::string description() const override { return "file " + path_.string(); }
  bool is_live() const override { return false; }

 private:
  std::filesystem::path path_;
  bool loop_;
  cv::VideoCapture capture_;
  int backend_ = cv::CAP_ANY;  // the one that opened the file, to reopen it for a loop
  cv::Mat frame_;
  uint64_t frames_this_pass_ = 0;
};

// Images of a directory (png, jpg, jpeg, bmp, tif, tiff, pgm, ppm; any case), in order of
// their file names; 16-bit and colour images are converted (to_mono8). A file that cannot be
// decoded is skipped, reported to `on_warning`, counted and left out of later passes. The
// directory is listed once, when constructed. `loop`: start over after the last image.
// Throws std::runtime_error naming the directory when it does not exist, cannot be listed or
// holds no image files.
class ImageDirectorySource final : public FrameSource {
 public:
  using WarningHandler = std::function<void(const std::string& message)>;

  explicit ImageDirectorySource(const std::filesystem::path& directory, bool loop = false,
                                WarningHandler on_warning = {});
  bool read(cv::Mat& mono8) override;
  std::string description() const override;
  bool is_live() const override { return false; }

  // The image files still in the list (undecodable ones leave it when met).
  const std::vector<std::filesystem::path>& files() const { return files_; }
  // Files skipped because they could not be decoded.
  uint64_t skipped_files() const { return skipped_files_; }

 private:
  std::filesystem::path directory_;
  bool loop_;
  WarningHandler on_warning_;
  std::vector<std::filesystem::path> files_;
  size_t next_ = 0;
  uint64_t skipped_files_ = 0;
};

// True for names ImageDirectorySource reads (by extension).
bool is_image_file_name(const std::filesystem::path& path);

}  // namespace mocap::capture
