// Frame sources (components/tracking/camera_source): conversion to mono8, directories of images,
// video files, the errors for missing input, and the camera_source plugin in a launched graph.
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "test/test_support.hpp"
#include "tracking/camera_source/camera_source.hpp"

namespace mocap::capture {
namespace {

namespace fs = std::filesystem;

// The message of the std::runtime_error that `open` throws ("" if it does not throw).
template <class Open>
std::string error_of(Open&& open) {
  try {
    open();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

cv::Mat grey(int value, cv::Size size = {32, 24}) {
  return cv::Mat(size, CV_8U, cv::Scalar(value));
}

// --- to_mono8 -------------------------------------------------------------------------------

TEST(ToMono8, ConvertsColourAndSixteenBitFrames) {
  cv::Mat mono8;

  cv::Mat source = grey(77);
  to_mono8(source, mono8);
  EXPECT_EQ(mono8.type(), CV_8UC1);
  EXPECT_EQ(mono8.at<uint8_t>(3, 4), 77);
  EXPECT_NE(mono8.data, source.data);  // a copy: the source may reuse its buffer

  cv::Mat bgr(24, 32, CV_8UC3, cv::Scalar(10, 100, 200));  // blue, green, red
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  to_mono8(bgr, mono8);
  EXPECT_EQ(mono8.type(), CV_8UC1);
  EXPECT_EQ(mono8.at<uint8_t>(0, 0), expected.at<uint8_t>(0, 0));
  EXPECT_NEAR(mono8.at<uint8_t>(0, 0), 0.114 * 10 + 0.587 * 100 + 0.299 * 200, 1);

  cv::Mat bgra(24, 32, CV_8UC4, cv::Scalar(10, 100, 200, 255));
  to_mono8(bgra, mono8);
  EXPECT_EQ(mono8.at<uint8_t>(5, 5), expected.at<uint8_t>(0, 0));

  cv::Mat sixteen(24, 32, CV_16U, cv::Scalar(0x1234));
  sixteen.at<uint16_t>(0, 0) = 65535;
  to_mono8(sixteen, mono8);
  EXPECT_EQ(mono8.type(), CV_8UC1);
  EXPECT_EQ(mono8.at<uint8_t>(1, 1), 0x12);
  EXPECT_EQ(mono8.at<uint8_t>(0, 0), 255);

  cv::Mat sixteen_colour(24, 32, CV_16UC3, cv::Scalar(0x4000, 0x4000, 0x4000));
  to_mono8(sixteen_colour, mono8);
  EXPECT_EQ(mono8.at<uint8_t>(2, 2), 0x40);

  cv::Mat unit(24, 32, CV_32F, cv::Scalar(0.5));
  to_mono8(unit, mono8);
  EXPECT_EQ(mono8.at<uint8_t>(0, 0), 128);
}

TEST(ToMono8, RejectsWhatItCannotRead) {
  cv::Mat mono8;
  EXPECT_THROW(to_mono8(cv::Mat(), mono8), std::invalid_argument);
  EXPECT_THROW(to_mono8(cv::Mat(4, 4, CV_8UC2, cv::Scalar::all(0)), mono8), std::invalid_argument);
  EXPECT_THROW(to_mono8(cv::Mat(4, 4, CV_8S, cv::Scalar(0)), mono8), std::invalid_argument);
}

// --- ImageDirectorySource -------------------------------------------------------------------

TEST(ImageDirectorySource, ReadsImagesInNameOrderAsMono8) {
  test::TempDir dir;
  // Written out of order; read back in name order. Other files are not images.
  ASSERT_TRUE(cv::imwrite((dir / "frame_002.png").string(), grey(20)));
  ASSERT_TRUE(cv::imwrite((dir / "frame_000.png").string(), grey(0)));
  ASSERT_TRUE(cv::imwrite((dir / "frame_003.PNG").string(),
                          cv::Mat(24, 32, CV_8UC3, cv::Scalar(30, 30, 30))));
  cv::Mat sixteen(24, 32, CV_16U, cv::Scalar(40 * 256 + 100));
  ASSERT_TRUE(cv::imwrite((dir / "frame_004.png").string(), sixteen));
  ASSERT_TRUE(cv::imwrite((dir / "frame_001.bmp").string(), grey(10)));
  ASSERT_TRUE(cv::imwrite((dir / "frame_005.pgm").string(), grey(50)));
  test::write_file(dir / "notes.txt", "not an image");
  fs::create_directory(dir / "sub.png");  // a directory, whatever its name

  ImageDirectorySource source(dir.path());
  EXPECT_FALSE(source.is_live());
  ASSERT_EQ(source.files().size(), 6u);
  EXPECT_EQ(source.files()[0].filename(), "frame_000.png");
  EXPECT_NE(source.description().find("6 images"), std::string::npos);

  cv::Mat frame;
  for (int i = 0; i < 6; ++i) {
    ASSERT_TRUE(source.read(frame)) << "frame " << i;
    EXPECT_EQ(frame.type(), CV_8UC1);
    EXPECT_EQ(frame.size(), cv::Size(32, 24));
    EXPECT_EQ(frame.at<uint8_t>(12, 16), 10 * i) << "frame " << i;
  }
  EXPECT_FALSE(source.read(frame));
  EXPECT_FALSE(source.read(frame));  // and stays at the end
  EXPECT_EQ(source.frames_read(), 6u);
}

TEST(ImageDirectorySource, SkipsUndecodableFilesWithAWarning) {
  test::TempDir dir;
  ASSERT_TRUE(cv::imwrite((dir / "a.png").string(), grey(1)));
  test::write_file(dir / "b.png", "this is not a PNG");
  ASSERT_TRUE(cv::imwrite((dir / "c.png").string(), grey(3)));

  std::vector<std::string> warnings;
  ImageDirectorySource source(dir.path(), /*loop=*/true,
                              [&](const std::string& warning) { warnings.push_back(warning); });
  cv::Mat frame;
  std::vector<int> values;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(source.read(frame));
    values.push_back(frame.at<uint8_t>(0, 0));
  }
  EXPECT_EQ(values, (std::vector<int>{1, 3, 1, 3, 1}));
  EXPECT_EQ(source.skipped_files(), 1u);
  ASSERT_EQ(warnings.size(), 1u);  // once, not on every pass
  EXPECT_NE(warnings[0].find("b.png"), std::string::npos);
  EXPECT_EQ(source.files().size(), 2u);
}

TEST(ImageDirectorySource, LoopOfUndecodableFilesEnds) {
  test::TempDir dir;
  test::write_file(dir / "a.png", "junk");
  test::write_file(dir / "b.jpg", "junk");
  ImageDirectorySource source(dir.path(), /*loop=*/true);
  cv::Mat frame;
  EXPECT_FALSE(source.read(frame));
  EXPECT_EQ(source.skipped_files(), 2u);
}

TEST(ImageDirectorySource, MissingOrEmptyDirectoriesAreErrorsNamingThePath) {
  test::TempDir dir;
  const fs::path missing = dir / "no_such_folder";
  std::string error = error_of([&] { ImageDirectorySource source(missing); });
  EXPECT_NE(error.find(missing.string()), std::string::npos) << error;
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;

  test::write_file(dir / "file.png", "x");
  error = error_of([&] { ImageDirectorySource source(dir / "file.png"); });
  EXPECT_NE(error.find("not a directory"), std::string::npos) << error;

  fs::create_directory(dir / "empty");
  test::write_file(dir / "empty" / "readme.txt", "no images here");
  error = error_of([&] { ImageDirectorySource source(dir / "empty"); });
  EXPECT_NE(error.find((dir / "empty").string()), std::string::npos) << error;
  EXPECT_NE(error.find("no image files"), std::string::npos) << error;
}

// --- VideoFileSource ------------------------------------------------------------------------

// A short MJPG .avi whose frame i is a uniform grey of 20 + 20 i with a white square whose
// position moves with i.
fs::path write_video(const test::TempDir& dir, int frames) {
  const fs::path path = dir / "clip.avi";
  cv::VideoWriter writer(path.string(), cv::CAP_OPENCV_MJPEG,
                         cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25, cv::Size(64, 48), true);
  EXPECT_TRUE(writer.isOpened());
  for (int i = 0; i < frames; ++i) {
    cv::Mat frame(48, 64, CV_8UC3, cv::Scalar::all(20 + 20 * i));
    frame(cv::Rect(4 + 4 * i, 8, 8, 8)).setTo(cv::Scalar::all(255));
    writer.write(frame);
  }
  writer.release();
  return path;
}

void expect_frame(const cv::Mat& frame, int i) {
  ASSERT_EQ(frame.type(), CV_8UC1);
  ASSERT_EQ(frame.size(), cv::Size(64, 48));
  // JPEG is lossy: the background and the square, each within a few grey levels.
  EXPECT_NEAR(frame.at<uint8_t>(40, 50), 20 + 20 * i, 4) << "frame " << i;
  EXPECT_GT(frame.at<uint8_t>(12, 8 + 4 * i), 240) << "frame " << i;
}

TEST(VideoFileSource, ReadsBackAWrittenVideo) {
  test::TempDir dir;
  const fs::path path = write_video(dir, 8);
  VideoFileSource source(path);
  EXPECT_FALSE(source.is_live());
  EXPECT_NE(source.description().find("clip.avi"), std::string::npos);
  cv::Mat frame;
  for (int i = 0; i < 8; ++i) {
    ASSERT_TRUE(source.read(frame)) << "frame " << i;
    expect_frame(frame, i);
  }
  EXPECT_FALSE(source.read(frame));
  EXPECT_EQ(source.frames_read(), 8u);
}

TEST(VideoFileSource, LoopsBackToTheFirstFrame) {
  test::TempDir dir;
  VideoFileSource source(write_video(dir, 3), /*loop=*/true);
  cv::Mat frame;
  for (int i = 0; i < 7; ++i) {
    ASSERT_TRUE(source.read(frame)) << "read " << i;
    expect_frame(frame, i % 3);
  }
  EXPECT_EQ(source.frames_read(), 7u);
}

TEST(VideoFileSource, MissingOrUndecodableFilesAreErrorsNamingThePath) {
  test::TempDir dir;
  std::string error = error_of([&] { VideoFileSource source(dir / "missing.avi"); });
  EXPECT_NE(error.find((dir / "missing.avi").string()), std::string::npos) << error;
  EXPECT_NE(error.find("does not exist"), std::string::npos) << error;

  error = error_of([&] { VideoFileSource source(dir.path()); });
  EXPECT_NE(error.find("is a directory"), std::string::npos) << error;

  test::write_file(dir / "garbage.avi", std::string(4096, 'x'));
  error = error_of([&] { VideoFileSource source(dir / "garbage.avi"); });
  EXPECT_NE(error.find((dir / "garbage.avi").string()), std::string::npos) << error;
  EXPECT_NE(error.find("cannot decode"), std::string::npos) << error;
}

// --- VideoDeviceSource ----------------------------------------------------------------------

TEST(VideoDeviceSource, MissingDevicesAreErrorsNamingTheDevice) {
  std::string error = error_of([] { VideoDeviceSource source("/dev/video_missing_for_test"); });
  EXPECT_EQ(error, "/dev/video_missing_for_test: cannot open: No such file or directory");

  // An index no machine has: its device path.
  error = error_of([] { VideoDeviceSource source("97"); });
  EXPECT_EQ(error, "/dev/video97: cannot open: No such file or directory");

  // Something that exists but is no camera.
  error = error_of([] { VideoDeviceSource source("/dev/null"); });
  EXPECT_EQ(error, "/dev/null: VIDIOC_QUERYCAP failed: Inappropriate ioctl for device");
}

// --- The plugin -----------------------------------------------------------------------------

class CameraSourcePlugin : public testing::Test {
 protected:
  // Runs a one-group graph holding camera_source with `parameters` (YAML flow map body).
  std::pair<int, std::string> run(const std::string& parameters, double seconds = 2) {
    test::write_file(dir_ / "graph.yaml", fmt::format(R"(dds: {{enabled: false}}
groups:
  - name: camera
    components:
      - plugin: camera_source
        name: camera
        parameters: {{{}}}
)",
                                                      parameters));
    return test::run_command({(test::bin_dir() / "mocap_launch").string(),
                              (dir_ / "graph.yaml").string(), "--duration",
                              fmt::format("{}", seconds)});
  }

  test::TempDir dir_;
};

TEST_F(CameraSourcePlugin, PublishesADirectoryThenStopsAtItsEnd) {
  fs::create_directory(dir_ / "frames");
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(cv::imwrite((dir_ / "frames" / fmt::format("{}.png", i)).string(), grey(i)));
  }
  auto [code, output] = run(fmt::format(
      "directory: \"{}\", rate_hz: 50, wait_for_subscriber: false", (dir_ / "frames").string()));
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find("end of input after 3 frames"), std::string::npos) << output;
  EXPECT_NE(output.find("published 3 frames"), std::string::npos) << output;
}

TEST_F(CameraSourcePlugin, NeedsExactlyOneSource) {
  auto [code, output] = run("rate_hz: 10", 1);
  EXPECT_NE(code, 0);
  EXPECT_NE(output.find("set exactly one of device, file and directory (got none)"),
            std::string::npos)
      << output;

  fs::create_directory(dir_ / "frames");
  std::tie(code, output) =
      run(fmt::format("file: \"{0}/a.avi\", directory: \"{0}\"", dir_.path().string()), 1);
  EXPECT_NE(code, 0);
  EXPECT_NE(output.find("(got file and directory)"), std::string::npos) << output;

  std::tie(code, output) = run(fmt::format("directory: \"{}/missing\"", dir_.path().string()), 1);
  EXPECT_NE(code, 0);
  EXPECT_NE(output.find(dir_.path().string() + "/missing' does not exist"), std::string::npos)
      << output;
}

// A negative size is not "the device's own" (0): the options are refused before the device is
// opened, naming the field.
TEST(VideoDeviceOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(VideoDeviceOptions{}.problem(), std::nullopt);
  EXPECT_EQ(VideoDeviceOptions{.width = -640}.problem(), "width: -640 is below 0");
  EXPECT_EQ((VideoDeviceOptions{.width = 640, .height = -1}.problem()), "height: -1 is below 0");
  try {
    VideoDeviceSource source("/nonexistent/video0", {.width = -640});
    ADD_FAILURE() << "a negative width accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "VideoDeviceOptions::width: -640 is below 0");
  }
}

}  // namespace
}  // namespace mocap::capture
