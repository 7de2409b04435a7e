// The runtime's configuration reader (mocap/config_reader.hpp) with Eigen vectors, for the
// components' own files: scenes, rigs, turrets.
#pragma once

#include <limits>

#include <Eigen/Core>
#include <mocap/config_reader.hpp>

namespace mocap {

using YamlKeys = ConfigKeys;

template <class Error>
class YamlReader : public ConfigReader<Error> {
 public:
  using ConfigReader<Error>::ConfigReader;

  template <int N>
  Eigen::Matrix<double, N, 1> vector(const YAML::Node& node, const char* key,
                                     double min = std::numeric_limits<double>::lowest(),
                                     double max = std::numeric_limits<double>::max()) const {
    if (!node.IsSequence() || node.size() != N) {
      this->fail(node, fmt::format("'{}' must be a list of {} numbers, not {}", key, N,
                                   this->describe(node)));
    }
    Eigen::Matrix<double, N, 1> value;
    for (int i = 0; i < N; ++i) value[i] = this->to_number(node[i], key, min, max);
    return value;
  }

  template <int N>
  Eigen::Matrix<double, N, 1> vector(const YAML::Node& map, const char* key,
                                     const Eigen::Matrix<double, N, 1>& fallback) const {
    YAML::Node node = map[key];
    return node ? vector<N>(node, key) : fallback;
  }
};

}  // namespace mocap
