#include <mocap/calibration/camera_file.hpp>

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <mocap/calibration/camera_factory.hpp>
#include <mocap/calibration/pinhole_camera.hpp>
#include <mocap/config_reader.hpp>

namespace mocap::calibration {
namespace {

// How far from 1 a pose quaternion's norm may be: hand-written quaternions with four or five
// decimals pass, a wrong element or a missing sign does not.
constexpr double kQuaternionNormTolerance = 1e-3;

// The camera file's own fields over the common configuration reader. Keys the reader does not
// know at the top are left alone: camera_info files hold rectification and projection matrices.
class Reader : public ConfigReader<CameraFileError> {
 public:
  Reader(const YAML::Node& root, std::string source)
      : ConfigReader(std::move(source)), root_(root) {}

  using ConfigReader::required;
  YAML::Node required(const char* key) const { return required(root_, key, "a camera file"); }

  int positive_int(const char* key) const {
    YAML::Node node = required(key);
    int value = 0;
    if (!node.IsScalar() || !YAML::convert<int>::decode(node, value) || value <= 0) {
      fail(node, fmt::format("'{}' must be a positive integer, not {}", key, describe(node)));
    }
    return value;
  }

  std::string text(const char* key, std::string fallback) const {
    YAML::Node node = root_[key];
    if (!node) return fallback;
    if (!node.IsScalar())
      fail(node, fmt::format("'{}' must be a text, not {}", key, describe(node)));
    return node.Scalar();
  }

  // The `data` of a {rows, cols, data} matrix, checked to hold `count` finite numbers.
  std::vector<double> matrix(const char* key, size_t count) const {
    YAML::Node node = required(key);
    YAML::Node data = node.IsMap() ? node["data"] : YAML::Node();
    if (!data || !data.IsSequence()) fail(node, fmt::format("'{}' needs a 'data' list", key));
    return numbers(data, std::string(key) + ".data", count);
  }

 private:
  YAML::Node root_;
};

std::shared_ptr<const CameraModel> read_pinhole(const Reader& reader, const YAML::Node& root,
                                                int width, int height) {
  std::vector<double> k = reader.matrix("camera_matrix", 9);
  PinholeIntrinsics intrinsics{k[0], k[4], k[2], k[5]};
  if (root["distortion_coefficients"]) {
    const YAML::Node coefficients = root["distortion_coefficients"];
    const YAML::Node data = coefficients.IsMap() ? coefficients["data"] : YAML::Node();
    size_t count = data && data.IsSequence() ? data.size() : 0;
    if (count != 4 && count != 5) count = 5;  // the error then names the expected count
    std::vector<double> d = reader.matrix("distortion_coefficients", count);
    for (size_t i = 0; i < d.size(); ++i) intrinsics.distortion[i] = d[i];
  }
  try {
    return std::make_shared<PinholeCamera>(width, height, intrinsics);
  } catch (const std::invalid_argument& e) {
    reader.fail(root["camera_matrix"], e.what());
  }
}

// Every model but the pinhole (which keeps camera_info's matrices) is a map named after it,
// with its parameters (camera_parameter_names) as keys.
bool has_named_parameters(std::string_view model) {
  return model != "pinhole" && is_camera_type(model);
}

std::shared_ptr<const CameraModel> read_named_parameters(const Reader& reader,
                                                         const std::string& model, int width,
                                                         int height) {
  const std::span<const std::string_view> keys = camera_parameter_names(model);
  YAML::Node node = reader.required(model.c_str());
  const std::string what = "'" + model + "'";
  reader.check_keys(node, std::vector<std::string>(keys.begin(), keys.end()), what);
  std::vector<double> parameters;
  for (std::string_view key : keys) {
    const std::string name(key);
    parameters.push_back(
        reader.to_number(reader.required(node, name.c_str(), what), model + "." + name));
  }
  try {
    return make_camera_model(model, width, height, parameters);
  } catch (const std::invalid_argument& e) {
    reader.fail(node, e.what());
  }
}

Eigen::Isometry3d read_pose(const Reader& reader, const YAML::Node& node) {
  reader.check_keys(node, {"translation", "rotation"}, "'pose'");
  std::vector<double> t =
      reader.numbers(reader.required(node, "translation", "'pose'"), "pose.translation", 3);
  YAML::Node rotation_node = reader.required(node, "rotation", "'pose'");
  std::vector<double> q = reader.numbers(rotation_node, "pose.rotation", 4);
  Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
  double norm = rotation.norm();
  if (!(std::abs(norm - 1) <= kQuaternionNormTolerance)) {
    reader.fail(rotation_node, fmt::format("'pose.rotation' [qx, qy, qz, qw] has norm {:.6g}, must "
                                           "be a unit quaternion (within {:g})",
                                           norm, kQuaternionNormTolerance));
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation.normalized().toRotationMatrix();
  pose.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return pose;
}

// The shortest text that reads back as the same double.
std::string number_text(double value) { return fmt::format("{}", value); }

std::string list_text(std::initializer_list<double> values) {
  std::string text = "[";
  for (double value : values) text += (text.size() > 1 ? ", " : "") + number_text(value);
  return text + "]";
}

// camera_name and frame_id are free text: quoted, so that names like "yes" or "1" stay strings.
std::string quoted(const std::string& text) {
  YAML::Emitter emitter;
  emitter << YAML::DoubleQuoted << text;
  return emitter.c_str();
}

CameraFile read_camera_file(const YAML::Node& root, const std::string& source) {
  if (!root.IsMap()) throw CameraFileError(source + ": a camera file is a YAML map");
  Reader reader(root, source);
  CameraFile camera;
  camera.name = reader.text("camera_name", "camera");
  camera.frame_id = reader.text("frame_id", camera.name);
  int width = reader.positive_int("image_width");
  int height = reader.positive_int("image_height");
  std::string model = reader.text("distortion_model", "plumb_bob");
  if (model == "plumb_bob" || model == "pinhole") {
    camera.model = read_pinhole(reader, root, width, height);
  } else if (has_named_parameters(model)) {
    camera.model = read_named_parameters(reader, model, width, height);
  } else {
    reader.fail(root["distortion_model"], "distortion_model '" + model +
                                              "' is not supported (plumb_bob, pinhole, eucm, "
                                              "mei, ucm)");
  }
  if (root["pose"]) camera.world_from_camera = read_pose(reader, root["pose"]);
  return camera;
}

}  // namespace

CameraFile parse_camera_file(const std::string& text, const std::string& source) {
  return read_camera_file(ConfigReader<CameraFileError>(source).parse(text), source);
}

CameraFile load_camera_file(const std::string& path) {
  return read_camera_file(ConfigReader<CameraFileError>(path).load(), path);
}

std::string format_camera_file(const CameraFile& camera) {
  if (!camera.model) throw std::invalid_argument("camera file: no camera model to write");
  const CameraModel& model = *camera.model;
  std::string text = "# Camera file of mocap-graph (calibration/camera_file.hpp).\n";
  text += "camera_name: " + quoted(camera.name) + "\n";
  if (camera.frame_id != camera.name) text += "frame_id: " + quoted(camera.frame_id) + "\n";
  text += fmt::format("image_width: {}\nimage_height: {}\n", model.width(), model.height());
  if (const auto* pinhole = dynamic_cast<const PinholeCamera*>(&model)) {
    const PinholeIntrinsics& k = pinhole->intrinsics();
    const auto& [k1, k2, p1, p2, k3] = k.distortion;
    text += "distortion_model: plumb_bob\n";
    text += "camera_matrix:\n  rows: 3\n  cols: 3\n  data: " +
            list_text({k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1}) + "\n";
    text += "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: " +
            list_text({k1, k2, p1, p2, k3}) + "\n";
    text += "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: " +
            list_text({1, 0, 0, 0, 1, 0, 0, 0, 1}) + "\n";
    text += "projection_matrix:\n  rows: 3\n  cols: 4\n  data: " +
            list_text({k.fx, 0, k.cx, 0, 0, k.fy, k.cy, 0, 0, 0, 1, 0}) + "\n";
  } else if (has_named_parameters(model.type())) {
    const std::vector<double> parameters = camera_parameters(model);
    const std::span<const std::string_view> keys = camera_parameter_names(model.type());
    text += fmt::format("distortion_model: {0}\n{0}:\n", model.type());
    for (size_t i = 0; i < keys.size(); ++i) {
      text += fmt::format("  {}: {}\n", keys[i], number_text(parameters[i]));
    }
  } else {
    throw std::invalid_argument("camera file: camera model '" + model.type() +
                                "' has no file form");
  }
  if (camera.world_from_camera) {
    const Eigen::Isometry3d& pose = *camera.world_from_camera;
    Eigen::Quaterniond q(pose.linear());
    // q and −q are the same rotation; one sign keeps files of one pose identical.
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    const Eigen::Vector3d& t = pose.translation();
    text += "pose:\n  translation: " + list_text({t.x(), t.y(), t.z()}) +
            "\n  rotation: " + list_text({q.x(), q.y(), q.z(), q.w()}) + "  # qx, qy, qz, qw\n";
  }
  return text;
}

void save_camera_file(const std::string& path, const CameraFile& camera) {
  std::string text = format_camera_file(camera);
  std::string partial = path + ".partial";
  {
    std::ofstream stream(partial, std::ios::trunc);
    if (!stream) {
      throw CameraFileError(path + ": cannot write the camera file: " + std::strerror(errno));
    }
    stream << text;
    stream.flush();
    if (!stream) {
      int error = errno;
      std::remove(partial.c_str());
      throw CameraFileError(path + ": cannot write the camera file: " + std::strerror(error));
    }
  }
  if (std::rename(partial.c_str(), path.c_str()) != 0) {
    int error = errno;
    std::remove(partial.c_str());
    throw CameraFileError(path + ": cannot write the camera file: " + std::strerror(error));
  }
}

}  // namespace mocap::calibration
