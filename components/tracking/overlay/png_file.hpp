// PNG files of 8-bit pictures, written with zlib alone: the overlay's snapshots without
// OpenCV's image codecs, whose Debian build brings GDAL, Poppler and HDF5 (about 150 MB) into
// every installation.
#pragma once

#include <string>

#include <opencv2/core/mat.hpp>

namespace mocap::overlay {

// Writes `picture` to `path` as a PNG (8 bits per channel, no interlace): CV_8UC1 as grey,
// CV_8UC3 as colour in OpenCV's BGR order. Returns an empty string on success, otherwise one
// line naming the path and what went wrong (unsupported layout, cannot open, write failed).
std::string write_png(const std::string& path, const cv::Mat& picture);

}  // namespace mocap::overlay
