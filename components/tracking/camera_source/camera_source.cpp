#include "tracking/camera_source/camera_source.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <system_error>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio/registry.hpp>

namespace mocap::capture {
namespace {

namespace fs = std::filesystem;

bool is_index(const std::string& device) {
  return !device.empty() && device.size() <= 4 &&
         std::all_of(device.begin(), device.end(), [](unsigned char c) { return std::isdigit(c); });
}

}  // namespace

void to_mono8(const cv::Mat& frame, cv::Mat& mono8) {
  if (frame.empty()) throw std::invalid_argument("to_mono8: empty frame");
  const int depth = frame.depth();
  const int channels = frame.channels();
  if (channels != 1 && channels != 3 && channels != 4) {
    throw std::invalid_argument(
        fmt::format("to_mono8: {} channels (1, 3 or 4 are read)", channels));
  }
  const cv::Mat* eight_bit = &frame;
  cv::Mat scaled;
  if (depth == CV_16U) {
    frame.convertTo(channels == 1 ? mono8 : scaled, CV_8U, 1.0 / 256);
    eight_bit = channels == 1 ? &mono8 : &scaled;
  } else if (depth == CV_32F || depth == CV_64F) {
    frame.convertTo(channels == 1 ? mono8 : scaled, CV_8U, 255.0);
    eight_bit = channels == 1 ? &mono8 : &scaled;
  } else if (depth != CV_8U) {
    throw std::invalid_argument("to_mono8: pixel type " + cv::typeToString(frame.type()) +
                                " (8-bit, 16-bit unsigned or floating point are read)");
  }
  if (channels == 3) {
    cv::cvtColor(*eight_bit, mono8, cv::COLOR_BGR2GRAY);
  } else if (channels == 4) {
    cv::cvtColor(*eight_bit, mono8, cv::COLOR_BGRA2GRAY);
  } else if (eight_bit == &frame) {
    frame.copyTo(mono8);
  }
}

bool is_image_file_name(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const char* const kExtensions[] = {".png", ".jpg",  ".jpeg", ".bmp",
                                            ".tif", ".tiff", ".pgm",  ".ppm"};
  return std::any_of(std::begin(kExtensions), std::end(kExtensions),
                     [&](const char* known) { return extension == known; });
}

// --- VideoDeviceSource --------------------------------------------------------------------

std::optional<std::string> VideoDeviceOptions::problem() const {
  if (width < 0) return fmt::format("width: {} is below 0", width);
  if (height < 0) return fmt::format("height: {} is below 0", height);
  return std::nullopt;
}

namespace {

std::string device_path(const std::string& device) {
  return is_index(device) ? "/dev/video" + device : device;
}

V4l2Capture open_device(const std::string& device, const VideoDeviceOptions& options,
                        std::unique_ptr<V4l2Io> io) {
  if (auto problem = options.problem()) {
    throw std::invalid_argument("VideoDeviceOptions::" + *problem);
  }
  return V4l2Capture(device_path(device), {.width = options.width, .height = options.height},
                     std::move(io));
}

}  // namespace

VideoDeviceSource::VideoDeviceSource(const std::string& device, const VideoDeviceOptions& options,
                                     std::unique_ptr<V4l2Io> io)
    : device_(device_path(device)), capture_(open_device(device, options, std::move(io))) {}

std::string VideoDeviceSource::description() const {
  return fmt::format("device {} ({}x{} {}, stamped {})", device_, capture_.width(),
                     capture_.height(), capture_.pixel_format(),
                     capture_.exposure() ? "mid-exposure" : "as the driver does");
}

bool VideoDeviceSource::read(cv::Mat& mono8) {
  do {
    last_ = capture_.read(mono8);
  } while (!last_);
  ++frames_read_;
  return true;
}

std::optional<std::chrono::system_clock::time_point> VideoDeviceSource::captured() const {
  if (!last_) return std::nullopt;
  return last_->captured;
}

// --- VideoFileSource ----------------------------------------------------------------------

VideoFileSource::VideoFileSource(fs::path path, bool loop) : path_(std::move(path)), loop_(loop) {
  std::error_code error;
  if (!fs::exists(path_, error)) {
    throw std::runtime_error(fmt::format("video file '{}' does not exist", path_.string()));
  }
  if (fs::is_directory(path_, error)) {
    throw std::runtime_error(fmt::format(
        "video file '{}' is a directory (use the directory parameter for images)", path_.string()));
  }
  // FFmpeg reads nearly everything; OpenCV's own MJPEG reader covers builds without it. Not
  // CAP_ANY: it would also try GStreamer and the image-sequence reader, which print errors
  // of their own for a file that is no video.
  for (cv::VideoCaptureAPIs backend : {cv::CAP_FFMPEG, cv::CAP_OPENCV_MJPEG}) {
    if (cv::videoio_registry::hasBackend(backend) && capture_.open(path_.string(), backend)) {
      backend_ = backend;
      return;
    }
  }
  throw std::runtime_error(fmt::format(
      "cannot decode video file '{}' (neither FFmpeg nor OpenCV's MJPEG reader reads it)",
      path_.string()));
}

bool VideoFileSource::read(cv::Mat& mono8) {
  if (!capture_.read(frame_) || frame_.empty()) {
    // A file without a single frame would otherwise loop forever.
    if (!loop_ || frames_this_pass_ == 0) return false;
    // Reopening is the one way back to the start that every backend supports (seeking to
    // frame 0 is approximate for some codecs).
    capture_.release();
    frames_this_pass_ = 0;
    if (!capture_.open(path_.string(), backend_) || !capture_.read(frame_) || frame_.empty()) {
      return false;
    }
  }
  to_mono8(frame_, mono8);
  ++frames_this_pass_;
  ++frames_read_;
  return true;
}

// --- ImageDirectorySource -----------------------------------------------------------------

ImageDirectorySource::ImageDirectorySource(const fs::path& directory, bool loop,
                                           WarningHandler on_warning)
    : directory_(directory), loop_(loop), on_warning_(std::move(on_warning)) {
  std::error_code error;
  if (!fs::exists(directory_, error)) {
    throw std::runtime_error(
        fmt::format("image directory '{}' does not exist", directory_.string()));
  }
  if (!fs::is_directory(directory_, error)) {
    throw std::runtime_error(
        fmt::format("image directory '{}' is not a directory", directory_.string()));
  }
  fs::directory_iterator entries(directory_, error);
  if (error) {
    throw std::runtime_error(
        fmt::format("cannot list image directory '{}': {}", directory_.string(), error.message()));
  }
  for (const fs::directory_entry& entry : entries) {
    if (entry.is_regular_file(error) && is_image_file_name(entry.path())) {
      files_.push_back(entry.path());
    }
  }
  if (files_.empty()) {
    throw std::runtime_error(fmt::format(
        "image directory '{}' holds no image files (png, jpg, jpeg, bmp, tif, tiff, pgm, ppm)",
        directory_.string()));
  }
  std::sort(files_.begin(), files_.end(), [](const fs::path& a, const fs::path& b) {
    return a.filename().string() < b.filename().string();
  });
}

std::string ImageDirectorySource::description() const {
  return fmt::format("directory {} ({} images)", directory_.string(), files_.size());
}

bool ImageDirectorySource::read(cv::Mat& mono8) {
  while (!files_.empty()) {
    if (next_ >= files_.size()) {
      if (!loop_) return false;
      next_ = 0;
    }
    const fs::path path = files_[next_];
    cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    std::string problem;
    if (image.empty()) {
      problem = "cannot be decoded";
    } else {
      try {
        to_mono8(image, mono8);
      } catch (const std::invalid_argument& e) {
        problem = e.what();
      }
    }
    if (problem.empty()) {
      ++next_;
      ++frames_read_;
      return true;
    }
    // Dropped from the list, so that a loop does not warn about it on every pass.
    files_.erase(files_.begin() + static_cast<std::ptrdiff_t>(next_));
    ++skipped_files_;
    if (on_warning_) {
      on_warning_(fmt::format("skipped image '{}': {} ({} skipped so far)", path.string(), problem,
                              skipped_files_));
    }
  }
  return false;
}

}  // namespace mocap::capture
