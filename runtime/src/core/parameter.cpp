#include <mocap/parameter.hpp>

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace mocap {
namespace {

std::string format_number(double value) {
  if (std::isfinite(value) && value == std::floor(value) && std::fabs(value) < 1e15) {
    return fmt::format("{:.1f}", value);
  }
  return fmt::format("{}", value);
}

std::string quote(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

template <class T, class Format>
std::string format_list(const std::vector<T>& values, Format format) {
  std::string out = "[";
  for (size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += ", ";
    out += format(values[i]);
  }
  return out + "]";
}

std::string format_bound(double value) {
  return value == std::floor(value) && std::fabs(value) < 1e15 ? fmt::format("{}", int64_t(value))
                                                               : fmt::format("{}", value);
}

// YAML's [] reads as an empty list of int, and fits a list of any type.
bool is_empty_list(const ParameterValue& value) {
  const auto* numbers = std::get_if<std::vector<int64_t>>(&value);
  return numbers != nullptr && numbers->empty();
}

}  // namespace

std::string_view to_string(ParameterType type) {
  switch (type) {
    case ParameterType::Bool:
      return "bool";
    case ParameterType::Int:
      return "int";
    case ParameterType::Double:
      return "double";
    case ParameterType::String:
      return "string";
    case ParameterType::IntList:
      return "list of int";
    case ParameterType::DoubleList:
      return "list of double";
    case ParameterType::StringList:
      return "list of string";
  }
  return "?";
}

ParameterType type_of(const ParameterValue& value) {
  return static_cast<ParameterType>(value.index());
}

std::string to_string(const ParameterValue& value) {
  return std::visit(
      [](const auto& v) -> std::string {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>) {
          return v ? "true" : "false";
        } else if constexpr (std::is_same_v<T, int64_t>) {
          return fmt::format("{}", v);
        } else if constexpr (std::is_same_v<T, double>) {
          return format_number(v);
        } else if constexpr (std::is_same_v<T, std::string>) {
          return quote(v);
        } else if constexpr (std::is_same_v<T, std::vector<int64_t>>) {
          return format_list(v, [](int64_t x) { return fmt::format("{}", x); });
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
          return format_list(v, format_number);
        } else {
          return format_list(v, quote);
        }
      },
      value);
}

std::string ParameterSpec::type_description() const {
  std::string text(to_string(type()));
  if (is_path) text += " (path)";
  if (min && max) {
    text += fmt::format(" in [{}, {}]", format_bound(*min), format_bound(*max));
  } else if (min) {
    text += fmt::format(" >= {}", format_bound(*min));
  } else if (max) {
    text += fmt::format(" <= {}", format_bound(*max));
  }
  return text;
}

std::optional<std::string> ParameterSpec::check(const ParameterValue& value) const {
  ParameterType expected = type();
  ParameterType given = type_of(value);
  bool int_for_double = (expected == ParameterType::Double && given == ParameterType::Int) ||
                        (expected == ParameterType::DoubleList && given == ParameterType::IntList);
  bool empty_list_for_list = expected >= ParameterType::IntList && is_empty_list(value);
  if (given != expected && !int_for_double && !empty_list_for_list) {
    return fmt::format("expects {}, got {} {}", type_description(), to_string(given),
                       to_string(value));
  }
  // NaN is in no range.
  auto out_of_range = [&](double x) { return (min && !(x >= *min)) || (max && !(x <= *max)); };
  ParameterValue coerced = coerce(value);
  if (const double* x = std::get_if<double>(&coerced); x && out_of_range(*x)) {
    return fmt::format("expects {}, got {}", type_description(), to_string(value));
  }
  if (const int64_t* x = std::get_if<int64_t>(&coerced); x && out_of_range(double(*x))) {
    return fmt::format("expects {}, got {}", type_description(), to_string(value));
  }
  if (const auto* xs = std::get_if<std::vector<double>>(&coerced)) {
    for (double x : *xs) {
      if (out_of_range(x)) {
        return fmt::format("expects {}, got {} (element {})", type_description(), to_string(value),
                           format_number(x));
      }
    }
  }
  if (const auto* xs = std::get_if<std::vector<int64_t>>(&coerced)) {
    for (int64_t x : *xs) {
      if (out_of_range(double(x))) {
        return fmt::format("expects {}, got {} (element {})", type_description(), to_string(value),
                           x);
      }
    }
  }
  return std::nullopt;
}

ParameterValue ParameterSpec::coerce(const ParameterValue& value) const {
  const int64_t* number = std::get_if<int64_t>(&value);
  const auto* numbers = std::get_if<std::vector<int64_t>>(&value);
  switch (type()) {
    case ParameterType::Double:
      return number ? ParameterValue(static_cast<double>(*number)) : value;
    case ParameterType::DoubleList:
      return numbers ? ParameterValue(std::vector<double>(numbers->begin(), numbers->end()))
                     : value;
    case ParameterType::StringList:
      return is_empty_list(value) ? ParameterValue(std::vector<std::string>{}) : value;
    default:
      return value;
  }
}

const ParameterValue& Parameters::find(std::string_view name) const {
  auto it = values_.find(name);
  if (it == values_.end()) {
    throw std::logic_error(fmt::format("parameter '{}' was not declared", name));
  }
  return it->second;
}

void Parameters::wrong_type(std::string_view name, std::string_view requested) const {
  throw std::logic_error(fmt::format("parameter '{}' is {}, read as {}", name,
                                     to_string(type_of(find(name))), requested));
}

}  // namespace mocap
