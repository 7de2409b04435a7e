#include <mocap/calibration/calibration_config.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string_view>

#include <mocap/calibration/camera_factory.hpp>
#include <mocap/spelling.hpp>
#include <nlohmann/json.hpp>

namespace mocap::calibration {
namespace {

using Json = nlohmann::json;

constexpr double kQuaternionNormTolerance = 1e-3;
constexpr double kRotationTolerance = 1e-4;
// The PixArt sensor: what "ir_data" comes from unless the entry says otherwise.
constexpr int kDefaultImageWidth = 1024;
constexpr int kDefaultImageHeight = 768;

std::string number_text(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

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

std::string describe(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      return value.get<bool>() ? "true" : "false";
    case Json::value_t::string:
      return "the string " + value.dump();
    case Json::value_t::array:
      return "a list of " + std::to_string(value.size());
    case Json::value_t::object:
      return "an object";
    default:
      return value.is_number() ? "the number " + value.dump()
                               : "a " + std::string(value.type_name());
  }
}

// A key path as messages print it: data[1].transform_chain[0].name, or [3][0].points.
class KeyPath {
 public:
  KeyPath() = default;
  KeyPath operator/(std::string_view key) const {
    return KeyPath(text_.empty() ? std::string(key) : text_ + "." + std::string(key));
  }
  KeyPath operator[](size_t index) const {
    return KeyPath(text_ + "[" + std::to_string(index) + "]");
  }
  const std::string& str() const { return text_; }

 private:
  explicit KeyPath(std::string text) : text_(std::move(text)) {}
  std::string text_;
};

// Parses JSON and refuses an object that repeats a key (the parser would keep the last one
// silently: a pasted "value" overriding the intended one).
Json parse_json(const std::string& text, const std::string& source) {
  struct Level {
    bool array = false;
    size_t index = 0;
    std::string key;
    std::set<std::string> keys;
  };
  std::vector<Level> stack;
  auto where = [&stack]() {
    std::string path;
    for (const Level& level : stack) {
      path += level.array ? "[" + std::to_string(level.index) + "]"
                          : (path.empty() ? "" : ".") + level.key;
    }
    return path;
  };
  auto track = [&](int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        stack.push_back(Level{event == Json::parse_event_t::array_start, 0, {}, {}});
        break;
      case Json::parse_event_t::key: {
        Level& level = stack.back();
        level.key = parsed.get<std::string>();
        if (!level.keys.insert(level.key).second) {
          throw CalibrationConfigError(source + ": " + where() + ": the key appears twice");
        }
        break;
      }
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        stack.pop_back();
        if (!stack.empty() && stack.back().array) ++stack.back().index;
        break;
      case Json::parse_event_t::value:
        if (!stack.empty() && stack.back().array) ++stack.back().index;
        break;
    }
    return true;
  };
  try {
    return Json::parse(text, track);
  } catch (const Json::out_of_range& e) {
    // A number beyond double's range ("1e400"): nlohmann reports it without a position.
    // "[json.exception.out_of_range.406] number overflow parsing '1e400'"
    const std::string what = e.what();
    const size_t bracket = what.find("] ");
    throw CalibrationConfigError(source + ": invalid JSON: " +
                                 (bracket == std::string::npos ? what : what.substr(bracket + 2)));
  } catch (const Json::parse_error& e) {
    // "[json.exception.parse_error.101] parse error at line 3, column 2: why"
    std::string what = e.what();
    const size_t at = what.find("parse error at ");
    if (at != std::string::npos) what = what.substr(at + std::strlen("parse error at "));
    const size_t colon = what.find(": ");
    std::string position = colon != std::string::npos ? what.substr(0, colon) : std::string();
    std::string reason = colon != std::string::npos ? what.substr(colon + 2) : what;
    throw CalibrationConfigError(source + ": invalid JSON at " + position + " (byte " +
                                 std::to_string(e.byte) + "): " + reason);
  }
}

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

// Reads typed values out of one JSON document; every error names the file and the key path.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const KeyPath& path, const std::string& what) const {
    throw CalibrationConfigError(source_ + ": " + (path.str().empty() ? "" : path.str() + ": ") +
                                 what);
  }

  const std::string& source() const { return source_; }

  void object(const Json& value, const KeyPath& path, const std::string& what) const {
    if (!value.is_object()) fail(path, what + ", not " + describe(value));
  }

  void array(const Json& value, const KeyPath& path, const std::string& what) const {
    if (!value.is_array()) fail(path, what + ", not " + describe(value));
  }

  // Keys beginning with '_' are comments: the seed's files switch entries off that way.
  void check_keys(const Json& map, const KeyPath& path,
                  const std::vector<std::string>& allowed) const {
    for (const auto& [key, value] : map.items()) {
      if (key.starts_with("_") || std::find(allowed.begin(), allowed.end(), key) != allowed.end()) {
        continue;
      }
      fail(path / key, "unknown key" + did_you_mean(key, allowed, "keys"));
    }
  }

  const Json& required(const Json& map, const std::string& key, const KeyPath& path) const {
    auto found = map.find(key);
    if (found == map.end()) fail(path, "needs '" + key + "'");
    return *found;
  }

  bool boolean(const Json& map, const std::string& key, const KeyPath& path, bool fallback) const {
    auto found = map.find(key);
    if (found == map.end()) return fallback;
    if (!found->is_boolean()) fail(path / key, "true or false, not " + describe(*found));
    return found->get<bool>();
  }

  std::string text(const Json& value, const KeyPath& path) const {
    if (!value.is_string()) fail(path, "a string, not " + describe(value));
    std::string out = value.get<std::string>();
    if (out.empty()) fail(path, "must not be empty");
    return out;
  }

  double number(const Json& value, const KeyPath& path) const {
    if (!value.is_number()) fail(path, "a number, not " + describe(value));
    return value.get<double>();
  }

  int integer(const Json& value, const KeyPath& path) const {
    const double x = number(value, path);
    if (x != std::floor(x) || std::abs(x) > 1e9) fail(path, "a whole number, not " + value.dump());
    return static_cast<int>(x);
  }

  std::vector<double> numbers(const Json& value, const KeyPath& path) const {
    array(value, path, "a list of numbers");
    std::vector<double> out;
    for (size_t i = 0; i < value.size(); ++i) out.push_back(number(value[i], path[i]));
    return out;
  }

  Eigen::Isometry3d transform(const Json& value, const KeyPath& path) const {
    const std::vector<double> values = numbers(value, path);
    try {
      return transform_from_values(values);
    } catch (const std::invalid_argument& e) {
      fail(path, e.what());
    }
  }

 private:
  std::string source_;
};

// A data file as read: its frames, each the cameras that saw the board then.
struct DataFileEntry {
  std::string camera;
  std::vector<std::optional<Eigen::Vector2d>> points;  // nullopt: not seen
};

struct DataFile {
  std::string path;
  std::vector<std::vector<DataFileEntry>> frames;
  std::vector<std::string> cameras;  // every camera named, in order of first appearance
};

DataFile read_data_file(const std::string& text, const std::string& path) {
  const Reader reader(path);
  const Json root = parse_json(text, path);
  const KeyPath top;
  reader.array(root, top, "a data file is a list of frames");
  DataFile file;
  file.path = path;
  for (size_t f = 0; f < root.size(); ++f) {
    const Json& frame = root[f];
    const KeyPath frame_path = top[f];
    reader.array(frame, frame_path, "a frame is a list of {\"camera\": name, \"points\": [...]}");
    std::vector<DataFileEntry> entries;
    for (size_t e = 0; e < frame.size(); ++e) {
      const Json& item = frame[e];
      const KeyPath item_path = frame_path[e];
      reader.object(item, item_path, "{\"camera\": name, \"points\": [[u, v], ...]}");
      reader.check_keys(item, item_path, {"camera", "Cam_id", "points", "stamp_ns"});
      DataFileEntry entry;
      const bool has_camera = item.contains("camera"), has_cam_id = item.contains("Cam_id");
      if (has_camera && has_cam_id) reader.fail(item_path, "'camera' and 'Cam_id' both given");
      if (!has_camera && !has_cam_id) reader.fail(item_path, "needs 'camera'");
      const char* camera_key = has_camera ? "camera" : "Cam_id";
      entry.camera = reader.text(item[camera_key], item_path / camera_key);
      for (const DataFileEntry& other : entries) {
        if (other.camera == entry.camera) {
          reader.fail(item_path / camera_key, "'" + entry.camera + "' appears twice in the frame");
        }
      }
      if (item.contains("stamp_ns")) reader.number(item["stamp_ns"], item_path / "stamp_ns");
      const Json& points = reader.required(item, "points", item_path);
      const KeyPath points_path = item_path / "points";
      reader.array(points, points_path, "a list of [u, v] (null: not seen)");
      for (size_t p = 0; p < points.size(); ++p) {
        if (points[p].is_null()) {
          entry.points.push_back(std::nullopt);
          continue;
        }
        if (!points[p].is_array() || points[p].size() != 2) {
          reader.fail(points_path[p], "[u, v] in pixels or null, not " + describe(points[p]));
        }
        entry.points.push_back(Eigen::Vector2d(reader.number(points[p][0], points_path[p][0]),
                                               reader.number(points[p][1], points_path[p][1])));
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

class ConfigReader {
 public:
  ConfigReader(std::string source, std::string base_directory)
      : reader_(std::move(source)), base_directory_(std::move(base_directory)) {}

  CalibrationConfig read(const Json& root) {
    const KeyPath top;
    reader_.object(root, top,
                   "the configuration is an object with 'transformations', "
                   "'cameras' and 'data'");
    reader_.check_keys(root, top, {"transformations", "cameras", "data"});
    CalibrationConfig config;
    config.source = reader_.source();
    const Json& transformations = reader_.required(root, "transformations", top);
    reader_.array(transformations, top / "transformations", "a list of transformations");
    for (size_t i = 0; i < transformations.size(); ++i) {
      config.transformations.push_back(
          transformation(transformations[i], (top / "transformations")[i], config));
    }
    const Json& cameras = reader_.required(root, "cameras", top);
    reader_.array(cameras, top / "cameras", "a list of cameras");
    for (size_t i = 0; i < cameras.size(); ++i) {
      config.cameras.push_back(camera(cameras[i], (top / "cameras")[i], config));
    }
    const Json& data = reader_.required(root, "data", top);
    reader_.array(data, top / "data", "a list of data entries");
    for (size_t i = 0; i < data.size(); ++i) {
      DataSpec entry = data_entry(data[i], (top / "data")[i], config);
      config.data.push_back(std::move(entry));
    }
    return config;
  }

 private:
  TransformSpec transformation(const Json& map, const KeyPath& path,
                               const CalibrationConfig& config) const {
    reader_.object(map, path, "a transformation is an object");
    reader_.check_keys(map, path, {"name", "global", "constant", "prior", "stiffness", "value"});
    TransformSpec spec;
    spec.name = reader_.text(reader_.required(map, "name", path), path / "name");
    for (const TransformSpec& other : config.transformations) {
      if (other.name == spec.name) {
        reader_.fail(path / "name", "'" + spec.name + "' is declared twice");
      }
    }
    spec.global = reader_.boolean(map, "global", path, false);
    spec.constant = reader_.boolean(map, "constant", path, false);
    spec.prior = reader_.boolean(map, "prior", path, false);
    if (spec.constant && spec.prior) {
      reader_.fail(path, "'constant' and 'prior' exclude each other: a constant is exact");
    }
    if (map.contains("stiffness")) {
      if (!spec.prior) reader_.fail(path / "stiffness", "only with \"prior\": true");
      spec.prior_stiffness = reader_.number(map["stiffness"], path / "stiffness");
      if (!(spec.prior_stiffness > 0)) {
        reader_.fail(path / "stiffness",
                     "must be positive, not " + number_text(spec.prior_stiffness));
      }
    }
    if (map.contains("value")) spec.value = reader_.transform(map["value"], path / "value");
    if ((spec.constant || spec.prior) && !spec.value) {
      reader_.fail(path, std::string("needs 'value' for ") +
                             (spec.constant ? "\"constant\": true" : "\"prior\": true"));
    }
    return spec;
  }

  CameraSpec camera(const Json& map, const KeyPath& path, const CalibrationConfig& config) const {
    reader_.object(map, path, "a camera is an object");
    reader_.check_keys(map, path, {"name", "type", "constant", "value"});
    CameraSpec spec;
    spec.name = reader_.text(reader_.required(map, "name", path), path / "name");
    for (const CameraSpec& other : config.cameras) {
      if (other.name == spec.name) {
        reader_.fail(path / "name", "'" + spec.name + "' is declared twice");
      }
    }
    spec.type = reader_.text(reader_.required(map, "type", path), path / "type");
    spec.constant = reader_.boolean(map, "constant", path, false);
    spec.value = reader_.numbers(reader_.required(map, "value", path), path / "value");
    if (!is_camera_type(spec.type)) {
      reader_.fail(path / "type", "unknown camera type '" + spec.type + "' (" + kCameraTypes + ")");
    }
    const std::string problem = camera_parameter_count_problem(spec.type, spec.value.size());
    if (!problem.empty()) reader_.fail(path / "value", problem);
    return spec;
  }

  DataSpec data_entry(const Json& map, const KeyPath& path, CalibrationConfig& config) {
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
      reader_.fail(path / "type", "unknown data type '" + spec.type + "' (ir_data, images)");
    }
    spec.camera = reader_.text(reader_.required(map, "camera", path), path / "camera");
    std::vector<std::string> camera_names;
    for (const CameraSpec& camera : config.cameras) camera_names.push_back(camera.name);
    if (std::find(camera_names.begin(), camera_names.end(), spec.camera) == camera_names.end()) {
      reader_.fail(path / "camera", "'" + spec.camera + "' is not a declared camera" +
                                        suggestion(spec.camera, camera_names));
    }
    const TransformSpec& per_shot = chain(map, path, config, spec);
    init(map, path, per_shot, spec);
    flags(map, path, spec, config);
    if (map.contains("draw_scale")) reader_.number(map["draw_scale"], path / "draw_scale");
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
    shots(data_file(spec, path / "data_file"), path, spec);
    return spec;
  }

  // Reads the chain into `spec` and returns its one per-shot transformation.
  const TransformSpec& chain(const Json& map, const KeyPath& path, const CalibrationConfig& config,
                             DataSpec& spec) const {
    const KeyPath chain_path = path / "transform_chain";
    const Json& links = reader_.required(map, "transform_chain", path);
    reader_.array(links, chain_path, "a list of {\"name\": transformation, \"direct\": bool}");
    if (links.empty()) reader_.fail(chain_path, "is empty: it needs the board's pose");
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
        reader_.fail(link_path / "name", "'" + link.name + "' is not a declared transformation" +
                                             suggestion(link.name, names));
      }
      if (!found->global) per_shot.push_back(&*found);
      spec.transform_chain.push_back(link);
    }
    if (per_shot.size() != 1) {
      std::vector<std::string> listed;
      for (const TransformSpec* t : per_shot) listed.push_back(t->name);
      reader_.fail(chain_path,
                   "needs exactly one per-shot transformation (the board's pose), has " +
                       std::to_string(per_shot.size()) +
                       (listed.empty() ? "" : ": " + join(listed)));
    }
    return *per_shot.front();
  }

  // "init": a transform value; or, as the seed's files have it, "none" or the name of the
  // chain's per-shot transformation, both leaving the start to the solver (a PnP per shot).
  void init(const Json& map, const KeyPath& path, const TransformSpec& per_shot,
            DataSpec& spec) const {
    auto found = map.find("init");
    if (found == map.end()) return;
    if (found->is_string()) {
      const std::string name = found->get<std::string>();
      if (name != "none" && name != per_shot.name) {
        reader_.fail(path / "init", "a transform value, \"none\" or '" + per_shot.name +
                                        "' (the chain's per-shot transformation), not '" + name +
                                        "'");
      }
      return;
    }
    spec.init = reader_.transform(*found, path / "init");
  }

  // visgeom's "parameters": the flags that mean something here go to `spec.flags`, the others
  // once to `config.ignored_flags`; a leading '_' switches one off.
  void flags(const Json& map, const KeyPath& path, DataSpec& spec,
             CalibrationConfig& config) const {
    static const std::vector<std::string> kHonoured = {"improve_detection", "show_outliers"};
    static const std::vector<std::string> kIgnored = {"check_extraction",    "user_guided",
                                                      "do_not_solve",        "do_not_solve_global",
                                                      "save_outlire_images", "draw_improved"};
    auto found = map.find("parameters");
    if (found == map.end()) return;
    const KeyPath list_path = path / "parameters";
    reader_.array(*found, list_path, "a list of visgeom flags (\"show_outliers\", ...)");
    for (size_t i = 0; i < found->size(); ++i) {
      const std::string flag = reader_.text((*found)[i], list_path[i]);
      const std::string name = flag.starts_with('_') ? flag.substr(1) : flag;
      const bool honoured = std::find(kHonoured.begin(), kHonoured.end(), name) != kHonoured.end();
      if (!honoured && std::find(kIgnored.begin(), kIgnored.end(), name) == kIgnored.end()) {
        std::vector<std::string> known = kHonoured;
        known.insert(known.end(), kIgnored.begin(), kIgnored.end());
        reader_.fail(list_path[i],
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
  void board(const Json& map, const KeyPath& path, DataSpec& spec) const {
    reader_.object(map, path, "{\"type\": \"checkboard\", \"rows\": R, \"cols\": C, \"size\": S}");
    reader_.check_keys(map, path, {"type", "rows", "cols", "size"});
    if (map.contains("type")) {
      const std::string type = reader_.text(map["type"], path / "type");
      if (type != "checkboard" && type != "chessboard") {
        reader_.fail(path / "type",
                     "'checkboard' (visgeom's name) or 'chessboard', not '" + type + "'");
      }
    }
    for (auto [key, count] : {std::pair{"rows", &spec.board_rows}, {"cols", &spec.board_columns}}) {
      *count = reader_.integer(reader_.required(map, key, path), path / key);
      if (*count < 2) {
        reader_.fail(path / key, "at least 2 inner corners, not " + std::to_string(*count));
      }
    }
    const double size = reader_.number(reader_.required(map, "size", path), path / "size");
    if (!(size > 0)) reader_.fail(path / "size", "must be positive, not " + number_text(size));
    for (int i = 0; i < spec.board_rows; ++i) {
      for (int j = 0; j < spec.board_columns; ++j) {
        spec.corners.push_back(static_cast<int>(spec.object_points.size()));
        spec.object_points.emplace_back(j * size, i * size, 0.0);
      }
    }
  }

  // visgeom's {"prefix": DIR, "names": [...]}: each image is prefix + name, as visgeom joins them.
  void images(const Json& map, const KeyPath& path, DataSpec& spec) const {
    reader_.object(map, path, "{\"prefix\": folder, \"names\": [file, ...]}");
    reader_.check_keys(map, path, {"prefix", "names"});
    const Json& prefix = reader_.required(map, "prefix", path);
    if (!prefix.is_string()) reader_.fail(path / "prefix", "a string, not " + describe(prefix));
    spec.data_file = prefix.get<std::string>();
    spec.data_path = "images";
    const Json& names = reader_.required(map, "names", path);
    reader_.array(names, path / "names", "a list of image files");
    if (names.empty()) reader_.fail(path / "names", "is empty");
    for (size_t i = 0; i < names.size(); ++i) {
      const std::filesystem::path file(spec.data_file +
                                       reader_.text(names[i], (path / "names")[i]));
      spec.image_files.push_back(file.is_absolute() || base_directory_.empty()
                                     ? file.string()
                                     : (std::filesystem::path(base_directory_) / file).string());
    }
  }

  int image_size(const Json& map, const char* key, const KeyPath& path, int fallback) const {
    auto found = map.find(key);
    if (found == map.end()) return fallback;
    const int size = reader_.integer(*found, path / key);
    if (size <= 0) reader_.fail(path / key, "must be positive, not " + std::to_string(size));
    return size;
  }

  void object(const Json& map, const KeyPath& path, DataSpec& spec) const {
    reader_.object(map, path, "{\"points\": [[x, y, z], ...], \"corners\": [i, ...]}");
    reader_.check_keys(map, path, {"points", "corners"});
    const Json& points = reader_.required(map, "points", path);
    reader_.array(points, path / "points", "a list of [x, y, z] in metres");
    if (points.empty()) reader_.fail(path / "points", "is empty");
    for (size_t i = 0; i < points.size(); ++i) {
      const KeyPath point_path = (path / "points")[i];
      if (!points[i].is_array() || points[i].size() != 3) {
        reader_.fail(point_path, "[x, y, z] in metres, not " + describe(points[i]));
      }
      spec.object_points.emplace_back(reader_.number(points[i][0], point_path[0]),
                                      reader_.number(points[i][1], point_path[1]),
                                      reader_.number(points[i][2], point_path[2]));
    }
    auto corners = map.find("corners");
    if (corners == map.end()) {
      for (size_t i = 0; i < spec.object_points.size(); ++i) {
        spec.corners.push_back(static_cast<int>(i));
      }
      return;
    }
    reader_.array(*corners, path / "corners", "a list of indices into 'points'");
    if (corners->empty()) reader_.fail(path / "corners", "is empty");
    for (size_t i = 0; i < corners->size(); ++i) {
      const KeyPath corner_path = (path / "corners")[i];
      const int index = reader_.integer((*corners)[i], corner_path);
      if (index < 0 || static_cast<size_t>(index) >= spec.object_points.size()) {
        reader_.fail(corner_path, std::to_string(index) + " is not a point: there are " +
                                      std::to_string(spec.object_points.size()));
      }
      if (std::find(spec.corners.begin(), spec.corners.end(), index) != spec.corners.end()) {
        reader_.fail(corner_path, std::to_string(index) + " appears twice");
      }
      spec.corners.push_back(index);
    }
  }

  // Each data file is read once, however many entries use it.
  const DataFile& data_file(const DataSpec& spec, const KeyPath& path) {
    auto cached = files_.find(spec.data_path);
    if (cached != files_.end()) return *cached->second;
    std::string error;
    const std::string text = read_text(spec.data_path, error);
    if (!error.empty()) {
      reader_.fail(path, "cannot read '" + spec.data_path + "': " + error);
    }
    auto file = std::make_unique<DataFile>(read_data_file(text, spec.data_path));
    return *files_.emplace(spec.data_path, std::move(file)).first->second;
  }

  void shots(const DataFile& file, const KeyPath& path, DataSpec& spec) const {
    size_t frames_with_camera = 0;
    for (size_t f = 0; f < file.frames.size(); ++f) {
      const std::vector<DataFileEntry>& frame = file.frames[f];
      for (size_t e = 0; e < frame.size(); ++e) {
        const DataFileEntry& entry = frame[e];
        if (entry.camera != spec.camera) continue;
        ++frames_with_camera;
        if (entry.points.size() != spec.corners.size()) {
          throw CalibrationConfigError(file.path + ": [" + std::to_string(f) + "][" +
                                       std::to_string(e) +
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
      reader_.fail(path, spec.data_path + " has no frame of camera '" + spec.camera + "'" +
                             (file.cameras.empty() ? " (it has no cameras)"
                                                   : " (it has " + join(file.cameras) + ")"));
    }
    if (spec.shots.empty()) {
      reader_.fail(path, "none of the " + std::to_string(frames_with_camera) + " frames of '" +
                             spec.camera + "' in " + spec.data_path + " has all " +
                             std::to_string(spec.corners.size()) + " corners");
    }
  }

  Reader reader_;
  std::string base_directory_;
  std::map<std::string, std::unique_ptr<DataFile>> files_;
};

void require_finite(std::span<const double> values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw std::invalid_argument("number " + std::to_string(i) + " is " + number_text(values[i]));
    }
  }
}

}  // namespace

bool DataSpec::has_flag(std::string_view flag) const {
  return std::find(flags.begin(), flags.end(), flag) != flags.end();
}

Eigen::Isometry3d transform_from_values(std::span<const double> values) {
  const size_t n = values.size();
  if (n != 3 && n != 6 && n != 7 && n != 12) {
    throw std::invalid_argument("3, 6, 7 or 12 numbers, not " + std::to_string(n));
  }
  require_finite(values);
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  if (n == 3) {
    transform.translation() = Eigen::Vector3d(values[0], values[1], 0);
    transform.linear() = Eigen::AngleAxisd(values[2], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  } else if (n == 6) {
    transform.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
    const Eigen::Vector3d rotation(values[3], values[4], values[5]);
    const double angle = rotation.norm();
    if (!std::isfinite(angle)) {
      throw std::invalid_argument("the rotation vector's length " + number_text(angle) +
                                  " is not a finite angle");
    }
    if (angle > 0) {
      transform.linear() = Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
    }
  } else if (n == 7) {
    transform.translation() = Eigen::Vector3d(values[0], values[1], values[2]);
    const Eigen::Quaterniond q(values[6], values[3], values[4], values[5]);
    if (std::abs(q.norm() - 1) > kQuaternionNormTolerance) {
      throw std::invalid_argument("the quaternion [qx, qy, qz, qw] has norm " +
                                  number_text(q.norm()) + ", not 1");
    }
    transform.linear() = q.normalized().toRotationMatrix();
  } else {
    Eigen::Matrix3d r;
    r << values[0], values[1], values[2], values[4], values[5], values[6], values[8], values[9],
        values[10];
    const double error = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm();
    // Negated so that NaN (from overflowing products) is refused too.
    if (!(error <= kRotationTolerance) || !(r.determinant() > 0)) {
      throw std::invalid_argument(
          "the 3x3 part is not a rotation (|R'R - I| = " + number_text(error) +
          ", det R = " + number_text(r.determinant()) + ")");
    }
    // Rounded matrices are off by a little; the transform must be exactly rigid.
    transform.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
    transform.translation() = Eigen::Vector3d(values[3], values[7], values[11]);
  }
  return transform;
}

std::vector<double> transform_to_values6(const Eigen::Isometry3d& transform) {
  const Eigen::AngleAxisd rotation(transform.rotation());
  const Eigen::Vector3d vector = rotation.angle() * rotation.axis();
  const Eigen::Vector3d t = transform.translation();
  return {t.x(), t.y(), t.z(), vector.x(), vector.y(), vector.z()};
}

CalibrationConfig parse_calibration_config(const std::string& text, const std::string& source,
                                           const std::string& base_directory) {
  return ConfigReader(source, base_directory).read(parse_json(text, source));
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
