// The calibration's JSON files read through the project's configuration reader
// (mocap/config_reader.hpp): its parser (yaml-cpp reads JSON), its file:line positions and its
// key checks, with JSON's own types (a quoted "3" is a string, not a number) and messages that
// name the key path as well as the line, JSON files nesting deeper than YAML ones:
// "calib.json:33: transformations[1].value: 3, 6, 7 or 12 numbers, not 5".
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include <mocap/calibration/calibration_config.hpp>
#include <mocap/config_reader.hpp>

namespace mocap::calibration {

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

enum class JsonType { kNull, kBoolean, kNumber, kString, kList, kObject };

class JsonReader {
 public:
  explicit JsonReader(std::string source) : reader_(std::move(source), "JSON") {}

  const std::string& source() const { return reader_.source(); }

  // The document in `text`; bad syntax fails with its line and column.
  YAML::Node parse(const std::string& text) const { return reader_.parse(text); }

  // "FILE:LINE: PATH: what", the line being `node`'s.
  [[noreturn]] void fail(const YAML::Node& node, const KeyPath& path,
                         const std::string& what) const {
    reader_.fail(node, path.str().empty() ? what : path.str() + ": " + what);
  }

  // A quoted scalar is a string; a plain one is null, true, false, a number or (YAML's
  // unquoted text, which JSON does not have) a string.
  static JsonType type_of(const YAML::Node& node);
  // "the string \"x\"", "the number 3", "a list of 2", "an object", "null", "true".
  static std::string describe(const YAML::Node& node);

  void object(const YAML::Node& value, const KeyPath& path, const std::string& what) const;
  void array(const YAML::Node& value, const KeyPath& path, const std::string& what) const;
  // Fails for a key outside `allowed` or a key given twice, suggesting the nearest allowed
  // key. Keys beginning with '_' are comments: the seed's files switch entries off that way.
  void check_keys(const YAML::Node& map, const KeyPath& path, ConfigKeys allowed) const;

  static bool has(const YAML::Node& map, const char* key) { return map[key].IsDefined(); }
  YAML::Node required(const YAML::Node& map, const char* key, const KeyPath& path) const;
  bool boolean(const YAML::Node& map, const char* key, const KeyPath& path, bool fallback) const;
  // A non-empty string.
  std::string text(const YAML::Node& value, const KeyPath& path) const;
  double number(const YAML::Node& value, const KeyPath& path) const;
  int integer(const YAML::Node& value, const KeyPath& path) const;
  std::vector<double> numbers(const YAML::Node& value, const KeyPath& path) const;
  // transform_from_values() of a list of numbers.
  Eigen::Isometry3d transform(const YAML::Node& value, const KeyPath& path) const;

 private:
  ConfigReader<CalibrationConfigError> reader_;
};

}  // namespace mocap::calibration
