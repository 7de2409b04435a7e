#include <mocap/calibration/calibration_config.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <string_view>

#include <fmt/format.h>
#include <mocap/calibration/camera_factory.hpp>
#include <mocap/spelling.hpp>

#include "data_file.hpp"
#include "json_reader.hpp"

namespace mocap::calibration {
namespace {

// The PixArt sensor: what "ir_data" comes from unless the entry says otherwise.
constexpr int kDefaultImageWidth = 1024;
constexpr int kDefaultImageHeight = 768;

std::string join(const std::vector<std::string>& words, std::string_view separator = ", ") {
  std::string out;
  for (const std::string& word : words) {
    if (!out.empty()) out += separator;
    out += word;
  }
  return out;
}

// " (did you mean 'x'?)" for a near miss of a declared name, otherwise nothing.
std::string suggestion(std::string_view word, const std::vector<std::string>& candidates) {
  // Names get a tighter bound than keys: "xi13" is more likely another transform than a typo
  // of "xi12".
  const std::string* best = nearest_spelling(word, candidates, 1);
  return best != nullptr ? " (did you mean '" + *best + "'?)" : std::string();
}

class CalibrationConfigReader {
 public:
  CalibrationConfigReader(std::string source, std::string base_directory)
      : reader_(std::move(source)), base_directory_(std::move(base_directory)) {}

  CalibrationConfig read(const std::string& text) {
    const YAML::Node root = reader_.parse(text);
    const KeyPath top;
    reader_.object(root, top,
                   "the configuration is an object with 'transformations', "
                   "'cameras' and 'data'");
    reader_.check_keys(root, top, {"transformations", "cameras", "data"});
    CalibrationConfig config;
    config.source = reader_.source();
    const YAML::Node& transformations = reader_.required(root, "transformations", top);
    reader_.array(transformations, top / "transformations", "a list of transformations");
    for (size_t i = 0; i < transformations.size(); ++i) {
      config.transformations.push_back(
          transformation(transformations[i], (top / "transformations")[i], config));
    }
    const YAML::Node& cameras = reader_.required(root, "cameras", top);
    reader_.array(cameras, top / "cameras", "a list of cameras");
    for (size_t i = 0; i < cameras.size(); ++i) {
      config.cameras.push_back(camera(cameras[i], (top / "cameras")[i], config));
    }
    const YAML::Node& data = reader_.required(root, "data", top);
    reader_.array(data, top / "data", "a list of data entries");
    for (size_t i = 0; i < data.size(); ++i) {
      DataSpec entry = data_entry(data[i], (top / "data")[i], config);
      config.data.push_back(std::move(entry));
    }
    return config;
  }

 private:
  TransformSpec transformation(const YAML::Node& map, const KeyPath& path,
                               const CalibrationConfig& config) const {
    reader_.object(map, path, "a transformation is an object");
    reader_.check_keys(map, path, {"name", "global", "constant", "prior", "stiffness", "value"});
    TransformSpec spec;
    spec.name = reader_.text(reader_.required(map, "name", path), path / "name");
    for (const TransformSpec& other : config.transformations) {
      if (other.name == spec.name) {
        reader_.fail(map["name"], path / "name", "'" + spec.name + "' is declared twice");
      }
    }
    spec.global = reader_.boolean(map, "global", path, false);
    spec.constant = reader_.boolean(map, "constant", path, false);
    spec.prior = reader_.boolean(map, "prior", path, false);
    if (spec.constant && spec.prior) {
      reader_.fail(map, path, "'constant' and 'prior' exclude each other: a constant is exact");
    }
    if (JsonReader::has(map, "stiffness")) {
      if (!spec.prior)
        reader_.fail(map["stiffness"], path / "stiffness", "only with \"prior\": true");
      spec.prior_stiffness = reader_.number(map["stiffness"], path / "stiffness");
      if (!(spec.prior_stiffness > 0)) {
        reader_.fail(map["stiffness"], path / "stiffness",
                     "must be positive, not " + fmt::format("{}", spec.prior_stiffness));
      }
    }
    if (JsonReader::has(map, "value")) spec.value = reader_.transform(map["value"], path / "value");
    if ((spec.constant || spec.prior) && !spec.value) {
      reader_.fail(map, path,
                   std::string("needs 'value' for ") +
                       (spec.constant ? "\"constant\": true" : "\"prior\": true"));
    }
    return spec;
  }

  CameraSpec camera(const YAML::Node& map, const KeyPath& path,
                    const CalibrationConfig& config) const {
    reader_.object(map, path, "a camera is an object");
    reader_.check_keys(map, path, {"name", "type", "constant", "value"});
    CameraSpec spec;
    spec.name = reader_.text(reader_.required(map, "name", path), path / "name");
    for (const CameraSpec& other : config.cameras) {
      if (other.name == spec.name) {
        reader_.fail(map["name"], path / "name", "'" + spec.name + "' is declared twice");
      }
    }
    spec.type = reader_.text(reader_.required(map, "type", path), path / "type");
    spec.constant = reader_.boolean(map, "constant", path, false);
    spec.value = reader_.numbers(reader_.required(map, "value", path), path / "value");
    if (!is_camera_type(spec.type)) {
      reader_.fail(map["type"], path / "type",
                   "unknown camera type '" + spec.type + "' (" + kCameraTypes + ")");
    }
    const std::string problem = camera_parameter_count_problem(spec.type, spec.value.size());
    if (!problem.empty()) reader_.fail(map["value"], path / "value", problem);
    return spec;
  }

  DataSpec data_entry(const YAML::Node& map, const KeyPath& path, CalibrationConfig& config) {
    reader_.object(map, path, "a data entry is an object");
    DataSpec spec;
    spec.type = reader_.text(reader_.required(map, "type", path), path / "type");
    // "parameters" and "draw_scale" (read by visgeom's draw_improved flag) are visgeom's.
    if (spec.type == "ir_data") {
      reader_.check_keys(map, path,
                         {"type", "camera", "transform_chain", "init", "image_width",
                          "image_height", "data_file", "object", "parameters", "draw_scale"});
    } else if (spec.type == "images") {
      reader_.check_keys(map, path,
                         {"type", "camera", "transform_chain", "init", "object", "parameters",
                          "images", "draw_scale"});
    } else {
      reader_.fail(map["type"], path / "type",
                   "unknown data type '" + spec.type + "' (ir_data, images)");
    }
    spec.camera = reader_.text(reader_.required(map, "camera", path), path / "camera");
    std::vector<std::string> camera_names;
    for (const CameraSpec& camera : config.cameras) camera_names.push_back(camera.name);
    if (std::find(camera_names.begin(), camera_names.end(), spec.camera) == camera_names.end()) {
      reader_.fail(
          map["camera"], path / "camera",
          "'" + spec.camera + "' is not a declared camera" + suggestion(spec.camera, camera_names));
    }
    const TransformSpec& per_shot = chain(map, path, config, spec);
    init(map, path, per_shot, spec);
    flags(map, path, spec, config);
    if (JsonReader::has(map, "draw_scale")) reader_.number(map["draw_scale"], path / "draw_scale");
    if (spec.type == "images") {
      board(reader_.required(map, "object", path), path / "object", spec);
      images(reader_.required(map, "images", path), path / "images", spec);
      return spec;
    }
    spec.image_width = image_size(map, "image_width", path, kDefaultImageWidth);
    spec.image_height = image_size(map, "image_height", path, kDefaultImageHeight);
    object(reader_.required(map, "object", path), path / "object", spec);
    spec.data_file = reader_.text(reader_.required(map, "data_file", path), path / "data_file");
    const std::filesystem::path file(spec.data_file);
    spec.data_path = file.is_absolute() || base_directory_.empty()
                         ? file.string()
                         : (std::filesystem::path(base_directory_) / file).string();
    shots(data_file(spec, map["data_file"], path / "data_file"), map, path, spec);
    return spec;
  }

  // Reads the chain into `spec` and returns its one per-shot transformation.
  const TransformSpec& chain(const YAML::Node& map, const KeyPath& path,
                             const CalibrationConfig& config, DataSpec& spec) const {
    const KeyPath chain_path = path / "transform_chain";
    const YAML::Node& links = reader_.required(map, "transform_chain", path);
    reader_.array(links, chain_path, "a list of {\"name\": transformation, \"direct\": bool}");
    if (links.size() == 0) reader_.fail(links, chain_path, "is empty: it needs the board's pose");
    std::vector<std::string> names;
    for (const TransformSpec& t : config.transformations) names.push_back(t.name);
    std::vector<const TransformSpec*> per_shot;
    for (size_t i = 0; i < links.size(); ++i) {
      const KeyPath link_path = chain_path[i];
      reader_.object(links[i], link_path, "{\"name\": transformation, \"direct\": bool}");
      reader_.check_keys(links[i], link_path, {"name", "direct"});
      ChainLink link;
      link.name = reader_.text(reader_.required(links[i], "name", link_path), link_path / "name");
      link.direct = reader_.boolean(links[i], "direct", link_path, true);
      auto found = std::find_if(config.transformations.begin(), config.transformations.end(),
                                [&](const TransformSpec& t) { return t.name == link.name; });
      if (found == config.transformations.end()) {
        reader_.fail(
            links[i]["name"], link_path / "name",
            "'" + link.name + "' is not a declared transformation" + suggestion(link.name, names));
      }
      if (!found->global) per_shot.push_back(&*found);
      spec.transform_chain.push_back(link);
    }
    if (per_shot.size() != 1) {
      std::vector<std::string> listed;
      for (const TransformSpec* t : per_shot) listed.push_back(t->name);
      reader_.fail(links, chain_path,
                   "needs exactly one per-shot transformation (the board's pose), has " +
                       std::to_string(per_shot.size()) +
                       (listed.empty() ? "" : ": " + join(listed)));
    }
    return *per_shot.front();
  }

  // "init": a transform value; or, as the seed's files have it, "none" or the name of the
  // chain's per-shot transformation, both leaving the start to the solver (a PnP per shot).
  void init(const YAML::Node& map, const KeyPath& path, const TransformSpec& per_shot,
            DataSpec& spec) const {
    const YAML::Node found = map["init"];
    if (!found) return;
    if (JsonReader::type_of(found) == JsonType::kString) {
      const std::string& name = found.Scalar();
      if (name != "none" && name != per_shot.name) {
        reader_.fail(found, path / "init",
                     "a transform value, \"none\" or '" + per_shot.name +
                         "' (the chain's per-shot transformation), not '" + name + "'");
      }
      return;
    }
    spec.init = reader_.transform(found, path / "init");
  }

  // visgeom's "parameters": the flags that mean something here go to `spec.flags`, the others
  // once to `config.ignored_flags`; a leading '_' switches one off.
  void flags(const YAML::Node& map, const KeyPath& path, DataSpec& spec,
             CalibrationConfig& config) const {
    static const std::vector<std::string> kHonoured = {"improve_detection", "show_outliers"};
    static const std::vector<std::string> kIgnored = {"check_extraction",    "user_guided",
                                                      "do_not_solve",        "do_not_solve_global",
                                                      "save_outlire_images", "draw_improved"};
    const YAML::Node found = map["parameters"];
    if (!found) return;
    const KeyPath list_path = path / "parameters";
    reader_.array(found, list_path, "a list of visgeom flags (\"show_outliers\", ...)");
    for (size_t i = 0; i < found.size(); ++i) {
      const std::string flag = reader_.text(found[i], list_path[i]);
      const std::string name = flag.starts_with('_') ? flag.substr(1) : flag;
      const bool honoured = std::find(kHonoured.begin(), kHonoured.end(), name) != kHonoured.end();
      if (!honoured && std::find(kIgnored.begin(), kIgnored.end(), name) == kIgnored.end()) {
        std::vector<std::string> known = kHonoured;
        known.insert(known.end(), kIgnored.begin(), kIgnored.end());
        reader_.fail(found[i], list_path[i],
                     "unknown visgeom flag '" + name + "'" + did_you_mean(name, known, "flags"));
      }
      if (flag.starts_with('_')) continue;
      if (honoured) {
        if (!spec.has_flag(name)) spec.flags.push_back(name);
      } else if (std::find(config.ignored_flags.begin(), config.ignored_flags.end(), name) ==
                 config.ignored_flags.end()) {
        config.ignored_flags.push_back(name);
      }
    }
  }

  // visgeom's chessboard: {"type": "checkboard", "rows": R, "cols": C, "size": S}, inner corners
  // row by row.
  void board(const YAML::Node& map, const KeyPath& path, DataSpec& spec) const {
    reader_.object(map, path, "{\"type\": \"checkboard\", \"rows\": R, \"cols\": C, \"size\": S}");
    reader_.check_keys(map, path, {"type", "rows", "cols", "size"});
    if (JsonReader::has(map, "type")) {
      const std::string type = reader_.text(map["type"], path / "type");
      if (type != "checkboard" && type != "chessboard") {
        reader_.fail(map["type"], path / "type",
                     "'checkboard' (visgeom's name) or 'chessboard', not '" + type + "'");
      }
    }
    for (auto [key, count] : {std::pair{"rows", &spec.board_rows}, {"cols", &spec.board_columns}}) {
      *count = reader_.integer(reader_.required(map, key, path), path / key);
      if (*count < 2) {
        reader_.fail(map[key], path / key,
                     "at least 2 inner corners, not " + std::to_string(*count));
      }
    }
    const double size = reader_.number(reader_.required(map, "size", path), path / "size");
    if (!(size > 0))
      reader_.fail(map["size"], path / "size", "must be positive, not " + fmt::format("{}", size));
    for (int i = 0; i < spec.board_rows; ++i) {
      for (int j = 0; j < spec.board_columns; ++j) {
        spec.corners.push_back(static_cast<int>(spec.object_points.size()));
        spec.object_points.emplace_back(j * size, i * size, 0.0);
      }
    }
  }

  // visgeom's {"prefix": DIR, "names": [...]}: each image is prefix + name, as visgeom joins them.
  void images(const YAML::Node& map, const KeyPath& path, DataSpec& spec) const {
    reader_.object(map, path, "{\"prefix\": folder, \"names\": [file, ...]}");
    reader_.check_keys(map, path, {"prefix", "names"});
    const YAML::Node& prefix = reader_.required(map, "prefix", path);
    if (JsonReader::type_of(prefix) != JsonType::kString) {
      reader_.fail(prefix, path / "prefix", "a string, not " + JsonReader::describe(prefix));
    }
    spec.data_file = prefix.Scalar();
    spec.data_path = "images";
    const YAML::Node& names = reader_.required(map, "names", path);
    reader_.array(names, path / "names", "a list of image files");
    if (names.size() == 0) reader_.fail(names, path / "names", "is empty");
    for (size_t i = 0; i < names.size(); ++i) {
      const std::filesystem::path file(spec.data_file +
                                       reader_.text(names[i], (path / "names")[i]));
      spec.image_files.push_back(file.is_absolute() || base_directory_.empty()
                                     ? file.string()
                                     : (std::filesystem::path(base_directory_) / file).string());
    }
  }

  int image_size(const YAML::Node& map, const char* key, const KeyPath& path, int fallback) const {
    const YAML::Node found = map[key];
    if (!found) return fallback;
    const int size = reader_.integer(found, path / key);
    if (size <= 0) reader_.fail(found, path / key, "must be positive, not " + std::to_string(size));
    return size;
  }

  void object(const YAML::Node& map, const KeyPath& path, DataSpec& spec) const {
    reader_.object(map, path, "{\"points\": [[x, y, z], ...], \"corners\": [i, ...]}");
    reader_.check_keys(map, path, {"points", "corners"});
    const YAML::Node& points = reader_.required(map, "points", path);
    reader_.array(points, path / "points", "a list of [x, y, z] in metres");
    if (points.size() == 0) reader_.fail(points, path / "points", "is empty");
    for (size_t i = 0; i < points.size(); ++i) {
      const KeyPath point_path = (path / "points")[i];
      if (!points[i].IsSequence() || points[i].size() != 3) {
        reader_.fail(points[i], point_path,
                     "[x, y, z] in metres, not " + JsonReader::describe(points[i]));
      }
      spec.object_points.emplace_back(reader_.number(points[i][0], point_path[0]),
                                      reader_.number(points[i][1], point_path[1]),
                                      reader_.number(points[i][2], point_path[2]));
    }
    const YAML::Node corners = map["corners"];
    if (!corners) {
      for (size_t i = 0; i < spec.object_points.size(); ++i) {
        spec.corners.push_back(static_cast<int>(i));
      }
      return;
    }
    reader_.array(corners, path / "corners", "a list of indices into 'points'");
    if (corners.size() == 0) reader_.fail(corners, path / "corners", "is empty");
    for (size_t i = 0; i < corners.size(); ++i) {
      const KeyPath corner_path = (path / "corners")[i];
      const int index = reader_.integer(corners[i], corner_path);
      if (index < 0 || static_cast<size_t>(index) >= spec.object_points.size()) {
        reader_.fail(corners[i], corner_path,
                     std::to_string(index) + " is not a point: there are " +
                         std::to_string(spec.object_points.size()));
      }
      if (std::find(spec.corners.begin(), spec.corners.end(), index) != spec.corners.end()) {
        reader_.fail(corners[i], corner_path, std::to_string(index) + " appears twice");
      }
      spec.corners.push_back(index);
    }
  }

  // Each data file is read once, however many entries use it.
  const DataFile& data_file(const DataSpec& spec, const YAML::Node& node, const KeyPath& path) {
    auto cached = files_.find(spec.data_path);
    if (cached != files_.end()) return *cached->second;
    std::string error;
    const std::string text = read_text(spec.data_path, error);
    if (!error.empty()) {
      reader_.fail(node, path, "cannot read '" + spec.data_path + "': " + error);
    }
    auto file = std::make_unique<DataFile>(read_data_file(text, spec.data_path));
    return *files_.emplace(spec.data_path, std::move(file)).first->second;
  }

  void shots(const DataFile& file, const YAML::Node& map, const KeyPath& path,
             DataSpec& spec) const {
    size_t frames_with_camera = 0;
    for (size_t f = 0; f < file.frames.size(); ++f) {
      const std::vector<DataFileEntry>& frame = file.frames[f];
      for (size_t e = 0; e < frame.size(); ++e) {
        const DataFileEntry& entry = frame[e];
        if (entry.camera != spec.camera) continue;
        ++frames_with_camera;
        if (entry.points.size() != spec.corners.size()) {
          throw CalibrationConfigError(file.path + ":" + std::to_string(entry.line) + ": [" +
                                       std::to_string(f) + "][" + std::to_string(e) +
                                       "].points: " + std::to_string(entry.points.size()) +
                                       " points, but " + reader_.source() + " " + path.str() +
                                       " has " + std::to_string(spec.corners.size()) + " corners");
        }
        Shot shot;
        shot.frame = f;
        for (const auto& point : entry.points) {
          if (point) shot.points.push_back(*point);
        }
        if (shot.points.size() == spec.corners.size()) spec.shots.push_back(std::move(shot));
      }
    }
    if (frames_with_camera == 0) {
      reader_.fail(map, path,
                   spec.data_path + " has no frame of camera '" + spec.camera + "'" +
                       (file.cameras.empty() ? " (it has no cameras)"
                                             : " (it has " + join(file.cameras) + ")"));
    }
    if (spec.shots.empty()) {
      reader_.fail(map, path,
                   "none of the " + std::to_string(frames_with_camera) + " frames of '" +
                       spec.camera + "' in " + spec.data_path + " has all " +
                       std::to_string(spec.corners.size()) + " corners");
    }
  }

  JsonReader reader_;
  std::string base_directory_;
  std::map<std::string, std::unique_ptr<DataFile>> files_;
};

}  // namespace

bool DataSpec::has_flag(std::string_view flag) const {
  return std::find(flags.begin(), flags.end(), flag) != flags.end();
}

CalibrationConfig parse_calibration_config(const std::string& text, const std::string& source,
                                           const std::string& base_directory) {
  return CalibrationConfigReader(source, base_directory).read(text);
}

CalibrationConfig load_calibration_config(const std::string& path) {
  std::string error;
  const std::string text = read_text(path, error);
  if (!error.empty()) {
    throw CalibrationConfigError(path + ": cannot read the calibration configuration: " + error);
  }
  return parse_calibration_config(text, path, std::filesystem::path(path).parent_path().string());
}

}  // namespace mocap::calibration
