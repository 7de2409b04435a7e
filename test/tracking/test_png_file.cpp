// The overlay's PNG files (components/tracking/overlay/png_file.hpp), read back by OpenCV's
// own decoder (libpng): every pixel as written, and one-line errors for what cannot be written.
#include <gtest/gtest.h>

#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "test/test_support.hpp"
#include "tracking/overlay/png_file.hpp"

namespace mocap::overlay {
namespace {

// Random pixels: any reordering, filtering or row-length mistake shows.
cv::Mat noise(int rows, int cols, int type) {
  cv::Mat picture(rows, cols, type);
  cv::RNG rng(7);
  rng.fill(picture, cv::RNG::UNIFORM, 0, 256);
  return picture;
}

TEST(PngFile, GreyReadsBackPixelForPixel) {
  test::TempDir dir;
  cv::Mat picture = noise(37, 53, CV_8UC1);  // odd sizes: no row padding to hide behind
  std::string path = (dir / "grey.png").string();
  ASSERT_EQ(write_png(path, picture), "");
  cv::Mat read = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(read.type(), CV_8UC1);
  ASSERT_EQ(read.size(), picture.size());
  EXPECT_EQ(cv::norm(read, picture, cv::NORM_INF), 0.0);
}

TEST(PngFile, ColourKeepsOpenCvsChannelOrder) {
  test::TempDir dir;
  cv::Mat picture = noise(41, 29, CV_8UC3);
  picture.at<cv::Vec3b>(0, 0) = {255, 0, 0};  // blue in BGR
  std::string path = (dir / "colour.png").string();
  ASSERT_EQ(write_png(path, picture), "");
  cv::Mat read = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(read.type(), CV_8UC3);
  ASSERT_EQ(read.size(), picture.size());
  EXPECT_EQ(read.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 0, 0));
  EXPECT_EQ(cv::norm(read, picture, cv::NORM_INF), 0.0);
}

TEST(PngFile, ARegionOfALargerPictureIsWrittenAsItself) {
  test::TempDir dir;
  cv::Mat whole = noise(60, 80, CV_8UC3);
  cv::Mat region = whole(cv::Rect(5, 7, 31, 19));  // not continuous in memory
  std::string path = (dir / "region.png").string();
  ASSERT_EQ(write_png(path, region), "");
  cv::Mat read = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(read.size(), region.size());
  EXPECT_EQ(cv::norm(read, region, cv::NORM_INF), 0.0);
}

TEST(PngFile, RefusesWhatItCannotWriteWithTheReason) {
  test::TempDir dir;
  std::string path = (dir / "x.png").string();
  EXPECT_EQ(write_png(path, cv::Mat(4, 4, CV_16UC1, cv::Scalar(1))),
            "cannot write " + path + ": a PNG picture is non-empty 8-bit grey or BGR");
  EXPECT_EQ(write_png(path, cv::Mat()),
            "cannot write " + path + ": a PNG picture is non-empty 8-bit grey or BGR");
  std::string missing = (dir / "no_such_folder" / "x.png").string();
  EXPECT_EQ(write_png(missing, noise(2, 2, CV_8UC1)),
            "cannot write " + missing + ": No such file or directory");
}

}  // namespace
}  // namespace mocap::overlay
