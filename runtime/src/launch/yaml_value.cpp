#include "launch/yaml_value.hpp"

#include <charconv>
#include <cmath>
#include <regex>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap {
namespace {

using Scalar = std::variant<bool, int64_t, double, std::string>;

Scalar scalar_value(const YAML::Node& node) {
  const std::string& text = node.Scalar();
  if (node.Tag() == "!") return text;  // quoted
  static const std::regex null_re("~|null|Null|NULL|");
  static const std::regex true_re("true|True|TRUE");
  static const std::regex false_re("false|False|FALSE");
  static const std::regex int_re("[-+]?[0-9]+");
  static const std::regex hex_re("0x[0-9a-fA-F]+");
  static const std::regex float_re(R"([-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?)");
  static const std::regex inf_re(R"([-+]?\.(inf|Inf|INF))");
  static const std::regex nan_re(R"(\.(nan|NaN|NAN))");
  if (std::regex_match(text, null_re)) throw std::invalid_argument("no value (null)");
  if (std::regex_match(text, true_re)) return true;
  if (std::regex_match(text, false_re)) return false;
  if (std::regex_match(text, int_re) || std::regex_match(text, hex_re)) {
    bool hex = text.starts_with("0x");
    const char* begin = text.data() + (hex ? 2 : (text[0] == '+' ? 1 : 0));
    int64_t value = 0;
    auto [end, error] = std::from_chars(begin, text.data() + text.size(), value, hex ? 16 : 10);
    if (error != std::errc() || end != text.data() + text.size()) {
      throw std::invalid_argument(fmt::format("integer {} is out of range", text));
    }
    return value;
  }
  if (std::regex_match(text, float_re)) {
    try {
      return std::stod(text);
    } catch (const std::out_of_range&) {
      throw std::invalid_argument(fmt::format("number {} is out of range", text));
    }
  }
  if (std::regex_match(text, inf_re)) {
    return text[0] == '-' ? -INFINITY : INFINITY;
  }
  if (std::regex_match(text, nan_re)) return NAN;
  return text;
}

}  // namespace

ParameterValue parameter_value_from_yaml(const YAML::Node& node) {
  if (node.IsScalar()) {
    return std::visit([](auto v) -> ParameterValue { return v; }, scalar_value(node));
  }
  if (node.IsNull()) throw std::invalid_argument("no value (null)");
  if (node.IsMap()) throw std::invalid_argument("a map, where a value or a list was expected");
  std::vector<Scalar> items;
  for (const YAML::Node& item : node) {
    if (!item.IsScalar()) {
      throw std::invalid_argument("a list holding a list or map; lists hold plain values");
    }
    items.push_back(scalar_value(item));
  }
  bool all_ints = true, all_numbers = true, all_strings = true;
  for (const Scalar& item : items) {
    all_ints &= std::holds_alternative<int64_t>(item);
    all_numbers &= std::holds_alternative<int64_t>(item) || std::holds_alternative<double>(item);
    all_strings &= std::holds_alternative<std::string>(item);
  }
  if (items.empty() || all_ints) {
    std::vector<int64_t> values;
    for (const Scalar& item : items) values.push_back(std::get<int64_t>(item));
    return values;
  }
  if (all_numbers) {
    std::vector<double> values;
    for (const Scalar& item : items) {
      values.push_back(std::holds_alternative<double>(item) ? std::get<double>(item)
                                                            : double(std::get<int64_t>(item)));
    }
    return values;
  }
  if (all_strings) {
    std::vector<std::string> values;
    for (const Scalar& item : items) values.push_back(std::get<std::string>(item));
    return values;
  }
  throw std::invalid_argument("a list mixing numbers, strings and booleans");
}

}  // namespace mocap
