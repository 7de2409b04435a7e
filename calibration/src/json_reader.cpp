#include "json_reader.hpp"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace mocap::calibration {
namespace {

// JSON's number syntax, loosely (a leading '+' passes): no inf, nan or hexadecimal.
bool parse_number(const std::string& text, double& value) {
  if (text.empty() || text.find_first_not_of("0123456789+-.eE") != std::string::npos) {
    return false;
  }
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

}  // namespace

JsonType JsonReader::type_of(const YAML::Node& node) {
  if (node.IsSequence()) return JsonType::kList;
  if (node.IsMap()) return JsonType::kObject;
  if (!node.IsScalar()) return JsonType::kNull;
  if (node.Tag() == "!") return JsonType::kString;
  const std::string& text = node.Scalar();
  if (text == "true" || text == "false") return JsonType::kBoolean;
  double value = 0;
  return parse_number(text, value) ? JsonType::kNumber : JsonType::kString;
}

std::string JsonReader::describe(const YAML::Node& node) {
  switch (type_of(node)) {
    case JsonType::kNull:
      return "null";
    case JsonType::kBoolean:
      return node.Scalar();
    case JsonType::kNumber:
      return "the number " + node.Scalar();
    case JsonType::kString:
      return "the string \"" + node.Scalar() + "\"";
    case JsonType::kList:
      return "a list of " + std::to_string(node.size());
    case JsonType::kObject:
      return "an object";
  }
  return "nothing";
}

void JsonReader::object(const YAML::Node& value, const KeyPath& path,
                        const std::string& what) const {
  if (!value.IsMap()) fail(value, path, what + ", not " + describe(value));
}

void JsonReader::array(const YAML::Node& value, const KeyPath& path,
                       const std::string& what) const {
  if (!value.IsSequence()) fail(value, path, what + ", not " + describe(value));
}

void JsonReader::check_keys(const YAML::Node& map, const KeyPath& path, ConfigKeys allowed) const {
  std::vector<std::string> keys(allowed.begin(), allowed.end());
  for (const auto& entry : map) {
    if (entry.first.IsScalar() && entry.first.Scalar().starts_with('_')) {
      keys.push_back(entry.first.Scalar());
    }
  }
  reader_.check_keys(map, keys, path.str().empty() ? "the top level" : path.str());
}

YAML::Node JsonReader::required(const YAML::Node& map, const char* key, const KeyPath& path) const {
  YAML::Node found = map[key];
  if (!found) fail(map, path, std::string("needs '") + key + "'");
  return found;
}

bool JsonReader::boolean(const YAML::Node& map, const char* key, const KeyPath& path,
                         bool fallback) const {
  const YAML::Node found = map[key];
  if (!found) return fallback;
  if (type_of(found) != JsonType::kBoolean) {
    fail(found, path / key, "true or false, not " + describe(found));
  }
  return found.Scalar() == "true";
}

std::string JsonReader::text(const YAML::Node& value, const KeyPath& path) const {
  if (type_of(value) != JsonType::kString) fail(value, path, "a string, not " + describe(value));
  if (value.Scalar().empty()) fail(value, path, "must not be empty");
  return value.Scalar();
}

double JsonReader::number(const YAML::Node& value, const KeyPath& path) const {
  double out = 0;
  if (type_of(value) != JsonType::kNumber || !parse_number(value.Scalar(), out)) {
    fail(value, path, "a number, not " + describe(value));
  }
  if (!std::isfinite(out)) fail(value, path, value.Scalar() + " is beyond a double's range");
  return out;
}

int JsonReader::integer(const YAML::Node& value, const KeyPath& path) const {
  const double x = number(value, path);
  if (x != std::floor(x) || std::abs(x) > 1e9) {
    fail(value, path, "a whole number, not " + value.Scalar());
  }
  return static_cast<int>(x);
}

std::vector<double> JsonReader::numbers(const YAML::Node& value, const KeyPath& path) const {
  array(value, path, "a list of numbers");
  std::vector<double> out;
  for (size_t i = 0; i < value.size(); ++i) out.push_back(number(value[i], path[i]));
  return out;
}

Eigen::Isometry3d JsonReader::transform(const YAML::Node& value, const KeyPath& path) const {
  const std::vector<double> values = numbers(value, path);
  try {
    return transform_from_values(values);
  } catch (const std::invalid_argument& e) {
    fail(value, path, e.what());
  }
}

}  // namespace mocap::calibration
