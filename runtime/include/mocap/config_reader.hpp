// Reading YAML configuration files with one-line errors that name the file and the line of the
// node at fault: "scene.yaml:12: 'period_s' must be a number, not 'fast'". Every configuration
// format of the project reads through it: launch files, bag metadata, camera files,
// constellation databases, synthetic and PixArt scenes, rigs, turrets, and (through
// calibration/src/json_reader.hpp) the calibration's JSON configuration and data files.
//
// A problem stops the reading: fail() throws the format's own Error (constructed from the
// one-line message), so callers keep catching the format's exception type. A format that
// reports every problem at once records them instead (record(), report_keys()) and goes on;
// problems() then lists them in file order.
//
//   mocap::ConfigReader<SceneError> reader(path);
//   YAML::Node root = reader.load();
//   reader.check_keys(root, {"camera", "boards"}, "the scene");
//   double rate = reader.positive(root, "rate_hz", 30.0, 1000.0);
#pragma once

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <mocap/spelling.hpp>

namespace mocap {

using ConfigKeys = std::initializer_list<std::string_view>;

// The error of a format with no exception type of its own.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <class Error = ConfigError>
class ConfigReader {
 public:
  // `source` names the file in messages: its path, or "launch.yaml" for text given directly.
  // `syntax` names the file's syntax in parse errors: a JSON file (yaml-cpp reads JSON too)
  // says "JSON error".
  explicit ConfigReader(std::string source, std::string syntax = "YAML")
      : source_(std::move(source)), syntax_(std::move(syntax)) {}

  const std::string& source() const { return source_; }

  // The YAML document in `text`. Bad YAML fails with the line and column of the fault:
  // "launch.yaml:4:1: YAML error: end of sequence flow not found".
  YAML::Node parse(const std::string& text) const {
    try {
      return YAML::Load(text);
    } catch (const YAML::Exception& e) {
      throw Error(fmt::format("{}:{}:{}: {} error: {}", source_, e.mark.line + 1, e.mark.column + 1,
                              syntax_, e.msg));
    }
  }

  // The YAML document in the file source() names.
  YAML::Node load() const {
    std::ifstream in(source_);
    if (!in) throw Error(fmt::format("{}: cannot read: {}", source_, std::strerror(errno)));
    std::stringstream text;
    text << in.rdbuf();
    return parse(text.str());
  }

  [[noreturn]] void fail(const YAML::Node& node, const std::string& what) const {
    throw Error(fmt::format("{}{}: {}", source_, where(node), what));
  }

  // Records a problem at `node` (or at 1-based `line`) without stopping.
  void record(const YAML::Node& node, const std::string& what) { record(line_of(node), what); }
  void record(int line, const std::string& what) {
    problems_.emplace_back(line > 0 ? line : std::numeric_limits<int>::max(),
                           line > 0 ? fmt::format("{}:{}: {}", source_, line, what)
                                    : fmt::format("{}: {}", source_, what));
  }
  // Records a problem with no place in the file (a command-line override), listed last.
  void record_outside(std::string message) {
    problems_.emplace_back(std::numeric_limits<int>::max(), std::move(message));
  }
  // The problems recorded, in file order.
  std::vector<std::string> problems() const {
    auto sorted = problems_;
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::string> messages;
    for (auto& [line, message] : sorted) messages.push_back(std::move(message));
    return messages;
  }

  // Fails for keys outside `allowed` and repeated keys, suggesting the nearest allowed key.
  // `what` names the map in messages ("the scene", "group 'tracking'").
  void check_keys(const YAML::Node& map, ConfigKeys allowed, std::string_view what) const {
    check_keys(map, std::vector<std::string>(allowed.begin(), allowed.end()), what);
  }
  void check_keys(const YAML::Node& map, const std::vector<std::string>& allowed,
                  std::string_view what) const {
    if (!map.IsMap()) fail(map, fmt::format("{} must be a map, not {}", what, describe(map)));
    auto problems = key_problems(map, &allowed, what);
    if (!problems.empty()) fail(problems.front().first, problems.front().second);
  }
  // As check_keys, but records every bad key of `map` and goes on; without `allowed`, only
  // repeated keys. False when there was one.
  bool report_keys(const YAML::Node& map, const std::vector<std::string>* allowed,
                   std::string_view what) {
    auto problems = key_problems(map, allowed, what);
    for (const auto& [node, message] : problems) record(node, message);
    return problems.empty();
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

  // A non-empty name.
  std::string text(const YAML::Node& node, std::string_view key) const {
    if (!node.IsScalar() || node.Scalar().empty()) {
      fail(node, fmt::format("'{}' must be a non-empty name, not {}", key, describe(node)));
    }
    return node.Scalar();
  }

  double to_number(const YAML::Node& node, std::string_view key,
                   double min = std::numeric_limits<double>::lowest(),
                   double max = std::numeric_limits<double>::max()) const {
    return in_range<double>(node, key, "a number", min, max);
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

  // `count` numbers (any count when 0).
  std::vector<double> numbers(const YAML::Node& node, std::string_view key,
                              size_t count = 0) const {
    if (!node.IsSequence() || (count > 0 && node.size() != count)) {
      fail(node, count > 0
                     ? fmt::format("'{}' must be a list of {} numbers, not {}", key, count,
                                   describe(node))
                     : fmt::format("'{}' must be a list of numbers, not {}", key, describe(node)));
    }
    std::vector<double> values;
    for (const YAML::Node& element : node) values.push_back(to_number(element, key));
    return values;
  }

  int64_t to_integer(const YAML::Node& node, std::string_view key, int64_t min, int64_t max) const {
    return in_range<int64_t>(node, key, "an integer", min, max);
  }

  int64_t integer(const YAML::Node& map, const char* key, int64_t fallback, int64_t min,
                  int64_t max) const {
    YAML::Node node = map[key];
    return node ? to_integer(node, key, min, max) : fallback;
  }

  bool to_boolean(const YAML::Node& node, std::string_view key) const {
    bool value = false;
    if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value)) {
      fail(node, fmt::format("'{}' must be true or false, not {}", key, describe(node)));
    }
    return value;
  }

  bool boolean(const YAML::Node& map, const char* key, bool fallback) const {
    YAML::Node node = map[key];
    return node ? to_boolean(node, key) : fallback;
  }

  // One of `choices` (by name); the index of the choice.
  size_t choice(const YAML::Node& map, const char* key, ConfigKeys choices, size_t fallback) const {
    YAML::Node node = map[key];
    if (!node) return fallback;
    if (node.IsScalar()) {
      auto found = std::find(choices.begin(), choices.end(), node.Scalar());
      if (found != choices.end()) return static_cast<size_t>(found - choices.begin());
    }
    fail(node, fmt::format("'{}' is {}, must be one of: {}", key, describe(node),
                           fmt::join(choices, ", ")));
  }

  // "'fast'", "a list of 3", "a map", "nothing": what a node is, for messages.
  static std::string describe(const YAML::Node& node) {
    if (node.IsScalar()) return "'" + node.Scalar() + "'";
    if (node.IsSequence()) return fmt::format("a list of {}", node.size());
    if (node.IsMap()) return "a map";
    return "nothing";
  }

  // The 1-based line of `node`, or 0 when it has none (an absent key).
  static int line_of(const YAML::Node& node) {
    return node.IsDefined() && node.Mark().line >= 0 ? node.Mark().line + 1 : 0;
  }

 private:
  // `node` read as a T (`kind` names it in the message: "a number"), finite, in [min, max].
  template <class T>
  T in_range(const YAML::Node& node, std::string_view key, std::string_view kind, T min,
             T max) const {
    T value{};
    bool read = node.IsScalar() && YAML::convert<T>::decode(node, value);
    if constexpr (std::is_floating_point_v<T>) read = read && std::isfinite(value);
    if (!read) fail(node, fmt::format("'{}' must be {}, not {}", key, kind, describe(node)));
    if (value < min || value > max) {
      fail(node, fmt::format("'{}' is {}, must be in [{}, {}]", key, value, min, max));
    }
    return value;
  }

  // Repeated keys, keys that are not names, and (with `allowed`) keys outside it.
  std::vector<std::pair<YAML::Node, std::string>> key_problems(
      const YAML::Node& map, const std::vector<std::string>* allowed, std::string_view what) const {
    std::vector<std::pair<YAML::Node, std::string>> problems;
    std::set<std::string> seen;
    for (const auto& entry : map) {
      const YAML::Node& key = entry.first;
      if (!key.IsScalar()) {
        problems.emplace_back(key, fmt::format("a key in {} is not a name", what));
      } else if (!seen.insert(key.Scalar()).second) {
        problems.emplace_back(key, fmt::format("'{}' appears twice in {}", key.Scalar(), what));
      } else if (allowed != nullptr &&
                 std::find(allowed->begin(), allowed->end(), key.Scalar()) == allowed->end()) {
        problems.emplace_back(key, fmt::format("unknown key '{}' in {}{}", key.Scalar(), what,
                                               did_you_mean(key.Scalar(), *allowed, "keys")));
      }
    }
    return problems;
  }

  static std::string where(const YAML::Node& node) {
    int line = line_of(node);
    return line > 0 ? fmt::format(":{}", line) : "";
  }
  std::string source_;
  std::string syntax_;
  std::vector<std::pair<int, std::string>> problems_;
};

}  // namespace mocap
