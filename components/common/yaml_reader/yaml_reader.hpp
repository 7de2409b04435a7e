// Reading a component's own YAML files (scenes, rigs) with one-line errors that name the file
// and line of the node at fault: "scene.yaml:12: 'period_s' must be a number, not 'fast'".
// Each file format derives its reader from YamlReader<ItsError>, so callers keep catching the
// format's own exception type.
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <set>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <Eigen/Core>
#include <mocap/spelling.hpp>

namespace mocap {

using YamlKeys = std::initializer_list<std::string_view>;

template <class Error>
class YamlReader {
 public:
  explicit YamlReader(std::string source) : source_(std::move(source)) {}

  const std::string& source() const { return source_; }

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    std::string where = source_;
    if (node.IsDefined() && node.Mark().line >= 0) {
      where += ":" + std::to_string(node.Mark().line + 1);
    }
    throw Error(where + ": " + what);
  }

  // Rejects keys outside `allowed` and repeated keys, suggesting the nearest allowed key.
  void check_keys(const YAML::Node& map, YamlKeys allowed, std::string_view what) const {
    if (!map.IsMap()) fail(map, fmt::format("{} must be a map, not {}", what, describe(map)));
    std::set<std::string> seen;
    for (const auto& entry : map) {
      const YAML::Node& key = entry.first;
      std::string name = key.IsScalar() ? key.Scalar() : std::string("(not a word)");
      if (!seen.insert(name).second) fail(key, fmt::format("'{}' appears twice in {}", name, what));
      if (std::find(allowed.begin(), allowed.end(), name) != allowed.end()) continue;
      fail(key, fmt::format("unknown key '{}' in {}{}", name, what,
                            did_you_mean(name, {allowed.begin(), allowed.end()}, "keys")));
    }
  }

  YAML::Node required(const YAML::Node& map, const char* key, std::string_view what) const {
    YAML::Node node = map[key];
    if (!node) fail(map, fmt::format("{} needs '{}'", what, key));
    return node;
  }

  // The list under `key`, or an empty one when the key is absent.
  YAML::Node list(const YAML::Node& map, const char* key) const {
    YAML::Node node = map[key];
    if (!node) return YAML::Node(YAML::NodeType::Sequence);
    if (!node.IsSequence()) {
      fail(node, fmt::format("'{}' must be a list, not {}", key, describe(node)));
    }
    return node;
  }

  std::string text(const YAML::Node& node, const char* key) const {
    if (!node.IsScalar() || node.Scalar().empty()) {
      fail(node, fmt::format("'{}' must be a non-empty name, not {}", key, describe(node)));
    }
    return node.Scalar();
  }

  double to_number(const YAML::Node& node, const char* key, double min, double max) const {
    double value = 0;
    if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
      fail(node, fmt::format("'{}' must be a number, not {}", key, describe(node)));
    }
    if (value < min || value > max) {
      fail(node, fmt::format("'{}' is {}, must be in [{}, {}]", key, value, min, max));
    }
    return value;
  }

  double number(const YAML::Node& map, const char* key, double fallback, double min,
                double max) const {
    YAML::Node node = map[key];
    return node ? to_number(node, key, min, max) : fallback;
  }

  // A number above 0 and up to `max` (periods, speeds, sizes).
  double positive(const YAML::Node& map, const char* key, double fallback, double max) const {
    YAML::Node node = map[key];
    if (!node) return fallback;
    double value = to_number(node, key, -max, max);
    if (!(value > 0)) fail(node, fmt::format("'{}' is {}, must be positive", key, value));
    return value;
  }

  int64_t integer(const YAML::Node& map, const char* key, int64_t fallback, int64_t min,
                  int64_t max) const {
    YAML::Node node = map[key];
    if (!node) return fallback;
    int64_t value = 0;
    if (!node.IsScalar() || !YAML::convert<int64_t>::decode(node, value)) {
      fail(node, fmt::format("'{}' must be an integer, not {}", key, describe(node)));
    }
    if (value < min || value > max) {
      fail(node, fmt::format("'{}' is {}, must be in [{}, {}]", key, value, min, max));
    }
    return value;
  }

  bool boolean(const YAML::Node& map, const char* key, bool fallback) const {
    YAML::Node node = map[key];
    if (!node) return fallback;
    bool value = false;
    if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value)) {
      fail(node, fmt::format("'{}' must be true or false, not {}", key, describe(node)));
    }
    return value;
  }

  template <int N>
  Eigen::Matrix<double, N, 1> vector(const YAML::Node& node, const char* key,
                                     double min = std::numeric_limits<double>::lowest(),
                                     double max = std::numeric_limits<double>::max()) const {
    if (!node.IsSequence() || node.size() != N) {
      fail(node, fmt::format("'{}' must be a list of {} numbers, not {}", key, N, describe(node)));
    }
    Eigen::Matrix<double, N, 1> value;
    for (int i = 0; i < N; ++i) value[i] = to_number(node[i], key, min, max);
    return value;
  }

  template <int N>
  Eigen::Matrix<double, N, 1> vector(const YAML::Node& map, const char* key,
                                     const Eigen::Matrix<double, N, 1>& fallback) const {
    YAML::Node node = map[key];
    return node ? vector<N>(node, key) : fallback;
  }

  // One of `choices` (by name); the index of the choice.
  size_t choice(const YAML::Node& map, const char* key, YamlKeys choices, size_t fallback) const {
    YAML::Node node = map[key];
    if (!node) return fallback;
    if (node.IsScalar()) {
      auto found = std::find(choices.begin(), choices.end(), node.Scalar());
      if (found != choices.end()) return static_cast<size_t>(found - choices.begin());
    }
    fail(node, fmt::format("'{}' is {}, must be one of: {}", key, describe(node),
                           fmt::join(choices, ", ")));
  }

  static std::string describe(const YAML::Node& node) {
    if (node.IsScalar()) return "'" + node.Scalar() + "'";
    if (node.IsSequence()) return fmt::format("a list of {}", node.size());
    if (node.IsMap()) return "a map";
    return "nothing";
  }

 private:
  std::string source_;
};

}  // namespace mocap
