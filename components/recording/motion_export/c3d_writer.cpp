#include "recording/motion_export/c3d_writer.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace mocap::motion_export {
namespace {

static_assert(std::endian::native == std::endian::little, "C3D is written in Intel byte order");

constexpr size_t kBlock = 512;
constexpr int kMaxPoints = 32767;            // POINT:USED is a signed 16-bit word
constexpr size_t kLabelsPerParameter = 255;  // a dimension is one byte
constexpr float kPointScale = -0.01f;        // negative: float data; |scale| is the residual's unit
constexpr double kMillimetres = 1000;

class Bytes {
 public:
  void i8(int value) { data_.push_back(static_cast<uint8_t>(value)); }
  void i16(int value) {
    const auto word = static_cast<uint16_t>(value);
    data_.push_back(static_cast<uint8_t>(word & 0xff));
    data_.push_back(static_cast<uint8_t>(word >> 8));
  }
  void f32(float value) {
    uint8_t bytes[4];
    std::memcpy(bytes, &value, 4);
    data_.insert(data_.end(), bytes, bytes + 4);
  }
  void text(const std::string& value) { data_.insert(data_.end(), value.begin(), value.end()); }
  void append(const Bytes& other) {
    data_.insert(data_.end(), other.data_.begin(), other.data_.end());
  }
  void pad_to_block() { data_.resize((data_.size() + kBlock - 1) / kBlock * kBlock, 0); }
  size_t size() const { return data_.size(); }
  std::vector<uint8_t>& data() { return data_; }

 private:
  std::vector<uint8_t> data_;
};

// A parameter's data type and dimensions as C3D codes them.
struct Value {
  int type;  // -1 character, 2 integer (16 bits), 4 real
  std::vector<int> dimensions;
  Bytes data;
};

Value text(const std::string& value) {
  Value v{-1, {static_cast<int>(value.size())}, {}};
  v.data.text(value);
  return v;
}

// Strings as a character matrix: each padded with blanks to the longest.
Value texts(const std::vector<std::string>& values) {
  size_t width = 1;
  for (const std::string& value : values) width = std::max(width, value.size());
  Value v{-1, {static_cast<int>(width), static_cast<int>(values.size())}, {}};
  for (const std::string& value : values)
    v.data.text(value + std::string(width - value.size(), ' '));
  return v;
}

Value integer(int value) {
  Value v{2, {}, {}};
  v.data.i16(value);
  return v;
}

Value integers(const std::vector<int>& values) {
  Value v{2, {static_cast<int>(values.size())}, {}};
  for (int value : values) v.data.i16(value);
  return v;
}

Value real(float value) {
  Value v{4, {}, {}};
  v.data.f32(value);
  return v;
}

class Parameters {
 public:
  void group(int id, const std::string& name, const std::string& description) {
    start_record(static_cast<int>(name.size()), -id, name);
    offset_ = bytes_.size();
    bytes_.i16(0);
    bytes_.i8(static_cast<int>(description.size()));
    bytes_.text(description);
    finish_record();
  }
  void add(int group, const std::string& name, const Value& value, const std::string& description) {
    start_record(static_cast<int>(name.size()), group, name);
    offset_ = bytes_.size();
    bytes_.i16(0);
    bytes_.i8(value.type);
    bytes_.i8(static_cast<int>(value.dimensions.size()));
    for (int dimension : value.dimensions) bytes_.i8(dimension);
    bytes_.append(value.data);
    bytes_.i8(static_cast<int>(description.size()));
    bytes_.text(description);
    finish_record();
  }
  // The section with its 4-byte heading, in whole blocks; the last record points nowhere.
  Bytes finish() {
    Bytes section;
    section.i8(1);
    section.i8(0x50);
    section.i8(0);   // blocks: below
    section.i8(84);  // Intel
    if (last_offset_ > 0) {
      bytes_.data()[last_offset_] = 0;
      bytes_.data()[last_offset_ + 1] = 0;
    }
    section.append(bytes_);
    section.pad_to_block();
    section.data()[2] = static_cast<uint8_t>(section.size() / kBlock);
    return section;
  }

 private:
  void start_record(int name_length, int id, const std::string& name) {
    bytes_.i8(name_length);
    bytes_.i8(id);
    bytes_.text(name);
  }
  // The offset from the offset word to the next record.
  void finish_record() {
    const size_t offset = bytes_.size() - offset_;
    bytes_.data()[offset_] = static_cast<uint8_t>(offset & 0xff);
    bytes_.data()[offset_ + 1] = static_cast<uint8_t>(offset >> 8);
    last_offset_ = offset_;
  }

  Bytes bytes_;
  size_t offset_ = 0, last_offset_ = 0;
};

enum Group { kPoint = 1, kAnalog = 2, kTrial = 3, kManufacturer = 4 };

// POINT:LABELS, LABELS2, ... each of up to 255 strings.
void add_in_parts(Parameters& parameters, const std::string& name,
                  const std::vector<std::string>& values, const std::string& description) {
  for (size_t start = 0, part = 1; start == 0 || start < values.size();
       start += kLabelsPerParameter, ++part) {
    const auto end = std::min(values.size(), start + kLabelsPerParameter);
    parameters.add(
        kPoint, part == 1 ? name : fmt::format("{}{}", name, part),
        texts({values.begin() + static_cast<std::ptrdiff_t>(start),
               values.begin() + static_cast<std::ptrdiff_t>(end)}),
        part == 1 ? description : fmt::format("{} {} to {}", description, start + 1, end));
  }
}

Bytes parameter_section(const PointTable& table, int data_start) {
  const size_t frames = table.frames.size();
  const auto rate = static_cast<float>(table.rate_hz);
  std::vector<std::string> labels, descriptions;
  for (const PointColumn& point : table.points) {
    labels.push_back(point.name);
    descriptions.push_back(point.description);
  }
  Parameters p;
  p.group(kPoint, "POINT", "3D point parameters");
  p.add(kPoint, "USED", integer(static_cast<int>(table.points.size())), "points per frame");
  p.add(kPoint, "FRAMES", integer(static_cast<int>(std::min<size_t>(frames, 65535))),
        "frames (unsigned)");
  p.add(kPoint, "DATA_START", integer(data_start), "first block of the 3D data");
  p.add(kPoint, "SCALE", real(kPointScale), "negative: real data; residual unit");
  p.add(kPoint, "RATE", real(rate), "frames per second");
  p.add(kPoint, "UNITS", text("mm"), "units of the points");
  add_in_parts(p, "LABELS", labels, "point labels");
  add_in_parts(p, "DESCRIPTIONS", descriptions, "point descriptions");
  p.add(kPoint, "X_SCREEN", text("+X"), "the screen's horizontal axis");
  p.add(kPoint, "Y_SCREEN", text("+Z"), "the screen's vertical axis: z up");
  p.group(kAnalog, "ANALOG", "analog data parameters");
  p.add(kAnalog, "USED", integer(0), "analog channels");
  p.add(kAnalog, "RATE", real(rate), "analog samples per second");
  p.group(kTrial, "TRIAL", "trial parameters");
  // 32-bit frame numbers as two 16-bit words, low first.
  p.add(kTrial, "ACTUAL_START_FIELD", integers({1, 0}), "first frame");
  p.add(kTrial, "ACTUAL_END_FIELD",
        integers({static_cast<int>(frames & 0xffff), static_cast<int>(frames >> 16)}),
        "last frame");
  p.add(kTrial, "CAMERA_RATE", real(rate), "frames per second");
  p.group(kManufacturer, "MANUFACTURER", "the writer");
  p.add(kManufacturer, "COMPANY", text("mocap-graph"), "");
  p.add(kManufacturer, "SOFTWARE", text("mocap_bag export"), "");
  return p.finish();
}

}  // namespace

void write_c3d(std::ostream& out, const PointTable& table) {
  if (table.points.size() > static_cast<size_t>(kMaxPoints)) {
    throw C3dError(fmt::format("{} points: C3D holds at most {}", table.points.size(), kMaxPoints));
  }
  for (const PointColumn& point : table.points) {
    if (point.name.size() > 255 || point.description.size() > 255) {
      throw C3dError(
          fmt::format("point '{}': C3D's labels hold at most 255 characters", point.name));
    }
  }
  if (table.rate_hz <= 0) throw C3dError("fewer than two frames: no frame rate to write");

  // The parameters' size does not depend on DATA_START's value: write once to learn it.
  const int parameter_blocks = static_cast<int>(parameter_section(table, 0).size() / kBlock);
  const int data_start = 2 + parameter_blocks;
  Bytes parameters = parameter_section(table, data_start);

  Bytes header;
  header.i8(2);  // the parameter section's first block
  header.i8(0x50);
  header.i16(static_cast<int>(table.points.size()));
  header.i16(0);  // analog measurements per frame
  header.i16(1);  // first frame
  header.i16(static_cast<int>(std::min<size_t>(table.frames.size(), 65535)));
  header.i16(0);  // maximum interpolation gap
  header.f32(kPointScale);
  header.i16(data_start);
  header.i16(0);  // analog samples per frame
  header.f32(static_cast<float>(table.rate_hz));
  header.pad_to_block();
  out.write(reinterpret_cast<const char*>(header.data().data()),
            static_cast<std::streamsize>(header.size()));
  out.write(reinterpret_cast<const char*>(parameters.data().data()),
            static_cast<std::streamsize>(parameters.size()));

  PointRows rows(table);
  Bytes frame;
  for (uint32_t f = 0; f < table.frames.size(); ++f) {
    rows.go_to(f);
    frame.data().clear();
    for (size_t p = 0; p < table.points.size(); ++p) {
      const PointSample* sample = rows.at(p);
      if (sample == nullptr) {
        for (float word : {0.f, 0.f, 0.f, -1.f}) frame.f32(word);
        continue;
      }
      const Eigen::Vector3d mm = sample->position * kMillimetres;
      frame.f32(static_cast<float>(mm.x()));
      frame.f32(static_cast<float>(mm.y()));
      frame.f32(static_cast<float>(mm.z()));
      frame.f32(static_cast<float>((sample->cameras & 0x7f) << 8));  // residual byte 0
    }
    out.write(reinterpret_cast<const char*>(frame.data().data()),
              static_cast<std::streamsize>(frame.size()));
  }
  // The data section in whole blocks.
  const auto written = static_cast<size_t>(table.frames.size()) * table.points.size() * 16;
  const std::string padding((kBlock - written % kBlock) % kBlock, '\0');
  out.write(padding.data(), static_cast<std::streamsize>(padding.size()));
}

}  // namespace mocap::motion_export
