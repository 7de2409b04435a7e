#include "tracking/overlay/png_file.hpp"

#include <array>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <vector>

#include <zlib.h>

namespace mocap::overlay {
namespace {

void append_u32(std::vector<uint8_t>& out, uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(value >> shift));
}

// A chunk: length, type, data, CRC-32 of type and data (PNG specification, section 5.3).
void append_chunk(std::vector<uint8_t>& out, const char (&type)[5],
                  const std::vector<uint8_t>& data) {
  append_u32(out, static_cast<uint32_t>(data.size()));
  size_t type_at = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  uLong crc = crc32(0L, out.data() + type_at, static_cast<uInt>(4 + data.size()));
  append_u32(out, static_cast<uint32_t>(crc));
}

}  // namespace

std::string write_png(const std::string& path, const cv::Mat& picture) {
  const int channels = picture.channels();
  if (picture.depth() != CV_8U || (channels != 1 && channels != 3) || picture.empty()) {
    return "cannot write " + path + ": a PNG picture is non-empty 8-bit grey or BGR";
  }
  // Each row: filter type 0 (none), then the pixels, colour reordered to PNG's RGB.
  const size_t row_bytes = static_cast<size_t>(picture.cols) * static_cast<size_t>(channels);
  std::vector<uint8_t> rows;
  rows.reserve((row_bytes + 1) * static_cast<size_t>(picture.rows));
  for (int y = 0; y < picture.rows; ++y) {
    const uint8_t* pixel = picture.ptr<uint8_t>(y);
    rows.push_back(0);
    if (channels == 1) {
      rows.insert(rows.end(), pixel, pixel + row_bytes);
    } else {
      for (int x = 0; x < picture.cols; ++x, pixel += 3) {
        rows.insert(rows.end(), {pixel[2], pixel[1], pixel[0]});
      }
    }
  }
  uLongf compressed_size = compressBound(static_cast<uLong>(rows.size()));
  std::vector<uint8_t> compressed(compressed_size);
  if (compress2(compressed.data(), &compressed_size, rows.data(), static_cast<uLong>(rows.size()),
                Z_DEFAULT_COMPRESSION) != Z_OK) {
    return "cannot write " + path + ": zlib failed to compress the picture";
  }
  compressed.resize(compressed_size);

  std::vector<uint8_t> header;
  append_u32(header, static_cast<uint32_t>(picture.cols));
  append_u32(header, static_cast<uint32_t>(picture.rows));
  header.insert(header.end(), {8, static_cast<uint8_t>(channels == 1 ? 0 : 2), 0, 0, 0});

  std::vector<uint8_t> file = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  append_chunk(file, "IHDR", header);
  append_chunk(file, "IDAT", compressed);
  append_chunk(file, "IEND", {});

  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return "cannot write " + path + ": " + std::strerror(errno);
  out.write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  out.close();
  if (!out) return "cannot write " + path + ": write failed (disk full?)";
  return {};
}

}  // namespace mocap::overlay
