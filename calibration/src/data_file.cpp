#include "data_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "json_reader.hpp"

namespace mocap::calibration {

std::string read_text(const std::string& path, std::string& error) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) {
    error = std::strerror(errno);
    return {};
  }
  std::stringstream text;
  text << stream.rdbuf();
  if (stream.bad()) error = std::strerror(errno);
  return text.str();
}

namespace {

DataFileEntry read_entry(const JsonReader& reader, const YAML::Node& item,
                         const KeyPath& item_path) {
  reader.object(item, item_path, "{\"camera\": name, \"points\": [[u, v], ...]}");
  reader.check_keys(item, item_path, {"camera", "Cam_id", "points", "stamp_ns"});
  DataFileEntry entry;
  const bool has_camera = JsonReader::has(item, "camera");
  const bool has_cam_id = JsonReader::has(item, "Cam_id");
  if (has_camera && has_cam_id) {
    reader.fail(item, item_path, "'camera' and 'Cam_id' both given");
  }
  const char* camera_key = has_cam_id ? "Cam_id" : "camera";
  entry.camera = reader.text(reader.required(item, camera_key, item_path), item_path / camera_key);
  if (JsonReader::has(item, "stamp_ns")) reader.number(item["stamp_ns"], item_path / "stamp_ns");
  const YAML::Node points = reader.required(item, "points", item_path);
  const KeyPath points_path = item_path / "points";
  reader.array(points, points_path, "a list of [u, v] (null: not seen)");
  entry.line = ConfigReader<>::line_of(points);
  for (size_t p = 0; p < points.size(); ++p) {
    const YAML::Node point = points[p];
    if (JsonReader::type_of(point) == JsonType::kNull) {
      entry.points.push_back(std::nullopt);
      continue;
    }
    if (!point.IsSequence() || point.size() != 2) {
      reader.fail(point, points_path[p],
                  "[u, v] in pixels or null, not " + JsonReader::describe(point));
    }
    entry.points.push_back(Eigen::Vector2d(reader.number(point[0], points_path[p][0]),
                                           reader.number(point[1], points_path[p][1])));
  }
  return entry;
}

}  // namespace

DataFile read_data_file(const std::string& text, const std::string& path) {
  const JsonReader reader(path);
  const YAML::Node root = reader.parse(text);
  const KeyPath top;
  reader.array(root, top, "a data file is a list of frames");
  DataFile file;
  file.path = path;
  for (size_t f = 0; f < root.size(); ++f) {
    const YAML::Node frame = root[f];
    const KeyPath frame_path = top[f];
    reader.array(frame, frame_path, "a frame is a list of {\"camera\": name, \"points\": [...]}");
    std::vector<DataFileEntry> entries;
    for (size_t e = 0; e < frame.size(); ++e) {
      const YAML::Node item = frame[e];
      DataFileEntry entry = read_entry(reader, item, frame_path[e]);
      for (const DataFileEntry& other : entries) {
        if (other.camera == entry.camera) {
          const char* camera_key = JsonReader::has(item, "Cam_id") ? "Cam_id" : "camera";
          reader.fail(item[camera_key], frame_path[e] / camera_key,
                      "'" + entry.camera + "' appears twice in the frame");
        }
      }
      if (std::find(file.cameras.begin(), file.cameras.end(), entry.camera) == file.cameras.end()) {
        file.cameras.push_back(entry.camera);
      }
      entries.push_back(std::move(entry));
    }
    file.frames.push_back(std::move(entries));
  }
  return file;
}

}  // namespace mocap::calibration
