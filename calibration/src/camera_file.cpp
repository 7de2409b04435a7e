#include <mocap/calibration/camera_file.hpp>

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include <mocap/calibration/pinhole_camera.hpp>

namespace mocap::calibration {
namespace {

class Reader {
 public:
  Reader(const YAML::Node& root, std::string source) : root_(root), source_(std::move(source)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    std::string where = source_;
    if (node && node.Mark().line >= 0) where += ":" + std::to_string(node.Mark().line + 1);
    throw CameraFileError(where + ": " + what);
  }

  YAML::Node required(const char* key) const {
    YAML::Node node = root_[key];
    if (!node) fail(root_, std::string("missing field '") + key + "'");
    return node;
  }

  int positive_int(const char* key) const {
    YAML::Node node = required(key);
    int value = 0;
    if (!node.IsScalar() || !YAML::convert<int>::decode(node, value) || value <= 0) {
      fail(node, std::string("'") + key + "' must be a positive integer");
    }
    return value;
  }

  std::string text(const char* key, std::string fallback) const {
    YAML::Node node = root_[key];
    if (!node) return fallback;
    if (!node.IsScalar()) fail(node, std::string("'") + key + "' must be a string");
    return node.Scalar();
  }

  // The `data` of a {rows, cols, data} matrix, checked to hold `count` finite numbers.
  std::vector<double> matrix(const char* key, size_t count) const {
    YAML::Node node = required(key);
    YAML::Node data = node.IsMap() ? node["data"] : YAML::Node();
    if (!data || !data.IsSequence()) fail(node, std::string("'") + key + "' needs a 'data' list");
    if (data.size() != count) {
      fail(data, std::string("'") + key + ".data' must have " + std::to_string(count) +
                     " numbers, has " + std::to_string(data.size()));
    }
    std::vector<double> values;
    for (const YAML::Node& element : data) {
      double value = 0;
      if (!element.IsScalar() || !YAML::convert<double>::decode(element, value) ||
          !std::isfinite(value)) {
        fail(element, std::string("'") + key + ".data' holds '" +
                          (element.IsScalar() ? element.Scalar() : "a non-number") +
                          "', not a finite number");
      }
      values.push_back(value);
    }
    return values;
  }

 private:
  YAML::Node root_;
  std::string source_;
};

}  // namespace

CameraFile parse_camera_file(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw CameraFileError(source + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) throw CameraFileError(source + ": a camera file is a YAML map");
  Reader reader(root, source);
  CameraFile camera;
  camera.name = reader.text("camera_name", "camera");
  camera.frame_id = reader.text("frame_id", camera.name);
  int width = reader.positive_int("image_width");
  int height = reader.positive_int("image_height");
  std::string model = reader.text("distortion_model", "plumb_bob");
  if (model != "plumb_bob" && model != "pinhole") {
    reader.fail(root["distortion_model"],
                "distortion_model '" + model + "' is not supported (plumb_bob, pinhole)");
  }
  std::vector<double> k = reader.matrix("camera_matrix", 9);
  PinholeIntrinsics intrinsics{k[0], k[4], k[2], k[5]};
  if (root["distortion_coefficients"]) {
    YAML::Node data = root["distortion_coefficients"]["data"];
    size_t count = data && data.IsSequence() ? data.size() : 0;
    if (count != 4 && count != 5) count = 5;  // the error then names the expected count
    std::vector<double> d = reader.matrix("distortion_coefficients", count);
    for (size_t i = 0; i < d.size(); ++i) intrinsics.distortion[i] = d[i];
  }
  try {
    camera.model = std::make_shared<PinholeCamera>(width, height, intrinsics);
  } catch (const std::invalid_argument& e) {
    reader.fail(root["camera_matrix"], e.what());
  }
  return camera;
}

CameraFile load_camera_file(const std::string& path) {
  std::ifstream stream(path);
  if (!stream) {
    throw CameraFileError(path + ": cannot read the camera file: " + std::strerror(errno));
  }
  std::stringstream text;
  text << stream.rdbuf();
  return parse_camera_file(text.str(), path);
}

}  // namespace mocap::calibration
