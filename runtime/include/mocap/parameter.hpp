// Typed component parameters: what a component declares and what it reads back.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

namespace mocap {

using ParameterValue = std::variant<bool, int64_t, double, std::string, std::vector<int64_t>,
                                    std::vector<double>, std::vector<std::string>>;

// Index-aligned with ParameterValue's alternatives.
enum class ParameterType { Bool, Int, Double, String, IntList, DoubleList, StringList };

std::string_view to_string(ParameterType type);  // "bool", "int", ..., "list of double"
ParameterType type_of(const ParameterValue& value);
std::string to_string(const ParameterValue& value);  // YAML flow style: 3, 0.5, [1, 2], "text"

struct ParameterSpec {
  std::string name;
  ParameterValue default_value;
  std::string description;
  // Inclusive bounds for numbers and for each element of number lists.
  std::optional<double> min;
  std::optional<double> max;
  // A file or directory (a string), or a list of them. A relative value in a launch file is taken
  // relative to that file's folder, one given with --set relative to the working directory.
  bool is_path = false;

  ParameterType type() const { return type_of(default_value); }
  // Why `value` is not acceptable for this parameter, or nullopt. An int is accepted for a
  // double (and converted by coerce()), nothing else is converted.
  std::optional<std::string> check(const ParameterValue& value) const;
  // `value` converted to this parameter's type; call after check() passed.
  ParameterValue coerce(const ParameterValue& value) const;
  // "double in [0, 1]", "list of string", ...
  std::string type_description() const;
};

namespace detail {
template <class T>
constexpr std::string_view cpp_type_name() {
  if constexpr (std::is_same_v<T, bool>) return "bool";
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) return "an integer type";
  if constexpr (std::is_floating_point_v<T>) return "double";
  if constexpr (std::is_same_v<T, std::string>) return "std::string";
  if constexpr (std::is_same_v<T, std::vector<double>>) return "std::vector<double>";
  if constexpr (std::is_same_v<T, std::vector<std::string>>) return "std::vector<std::string>";
  return "a vector of integers";
}

template <class T>
ParameterValue to_parameter_value(T value) {
  if constexpr (std::is_same_v<T, bool>) {
    return value;
  } else if constexpr (std::is_integral_v<T>) {
    return static_cast<int64_t>(value);
  } else if constexpr (std::is_floating_point_v<T>) {
    return static_cast<double>(value);
  } else if constexpr (std::is_convertible_v<T, std::string>) {
    return std::string(value);
  } else if constexpr (std::is_same_v<T, std::vector<int>>) {
    return std::vector<int64_t>(value.begin(), value.end());
  } else {
    return value;  // the remaining ParameterValue alternatives
  }
}
}  // namespace detail

// Validated parameter values of one component instance.
class Parameters {
 public:
  Parameters() = default;
  explicit Parameters(std::map<std::string, ParameterValue, std::less<>> values)
      : values_(std::move(values)) {}

  // The value as T: bool, an integer type, float, double, std::string, std::vector<int64_t>,
  // std::vector<int>, std::vector<double> or std::vector<std::string>. Throws
  // std::logic_error for an undeclared name or another type: that is a bug in the
  // component, not bad input, since values were validated against the declaration.
  template <class T>
  T get(std::string_view name) const;

  const std::map<std::string, ParameterValue, std::less<>>& values() const { return values_; }

 private:
  const ParameterValue& find(std::string_view name) const;
  [[noreturn]] void wrong_type(std::string_view name, std::string_view requested) const;

  std::map<std::string, ParameterValue, std::less<>> values_;
};

template <class T>
T Parameters::get(std::string_view name) const {
  const ParameterValue& value = find(name);
  if constexpr (std::is_same_v<T, float>) {
    if (const double* typed = std::get_if<double>(&value)) return static_cast<float>(*typed);
  } else if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, double> ||
                       std::is_same_v<T, std::string> || std::is_same_v<T, std::vector<int64_t>> ||
                       std::is_same_v<T, std::vector<double>> ||
                       std::is_same_v<T, std::vector<std::string>>) {
    if (const T* typed = std::get_if<T>(&value)) return *typed;
  } else if constexpr (std::is_integral_v<T>) {
    if (const int64_t* typed = std::get_if<int64_t>(&value)) return static_cast<T>(*typed);
  } else if constexpr (std::is_same_v<T, std::vector<int>>) {
    if (const auto* typed = std::get_if<std::vector<int64_t>>(&value)) {
      return std::vector<int>(typed->begin(), typed->end());
    }
  } else {
    static_assert(sizeof(T) == 0, "unsupported parameter type");
  }
  wrong_type(name, detail::cpp_type_name<T>());
}

}  // namespace mocap
