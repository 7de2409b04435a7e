#include "mocap_msg_to_idl/msg_to_idl.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <variant>

namespace mocap {
namespace {

// The .msg primitives and their IDL names (rosidl_adapter's MSG_TYPE_TO_IDL).
const std::map<std::string, std::string, std::less<>> kIdlPrimitive = {
    {"bool", "boolean"},   {"byte", "octet"},    {"char", "uint8"},      {"int8", "int8"},
    {"uint8", "uint8"},    {"int16", "int16"},   {"uint16", "uint16"},   {"int32", "int32"},
    {"uint32", "uint32"},  {"int64", "int64"},   {"uint64", "uint64"},   {"float32", "float"},
    {"float64", "double"}, {"string", "string"}, {"wstring", "wstring"},
};

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}
bool is_lower(char c) { return c >= 'a' && c <= 'z'; }
bool is_upper(char c) { return c >= 'A' && c <= 'Z'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}
std::string_view rtrim(std::string_view s) {
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}
std::string_view ltrim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  return s;
}
bool starts_with(std::string_view s, std::string_view prefix) {
  return s.substr(0, prefix.size()) == prefix;
}

// ROS 2's names: packages and fields "^[a-z][a-z0-9_]*$" without "__" or a trailing '_',
// messages "^[A-Z][A-Za-z0-9]*$", constants "^[A-Z]([A-Z0-9_]?[A-Z0-9]+)*$".
bool valid_package_or_field_name(std::string_view s) {
  if (s.empty() || !is_lower(s[0]) || s.back() == '_' || s.find("__") != std::string_view::npos)
    return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return is_lower(c) || is_digit(c) || c == '_'; });
}
bool valid_message_name(std::string_view s) {
  if (s.empty() || !is_upper(s[0])) return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return is_lower(c) || is_upper(c) || is_digit(c); });
}
bool valid_constant_name(std::string_view s) {
  if (s.empty() || !is_upper(s[0]) || s.back() == '_' || s.find("__") != std::string_view::npos)
    return false;
  return std::all_of(s.begin(), s.end(),
                     [](char c) { return is_upper(c) || is_digit(c) || c == '_'; });
}

class Failure {
 public:
  Failure(std::string_view file, int line) : file_(file), line_(line) {}
  [[noreturn]] void operator()(const std::string& reason) const {
    throw MsgError(std::string(file_) + ":" + std::to_string(line_) + ": " + reason);
  }

 private:
  std::string_view file_;
  int line_;
};

// An integer as Python's int() reads it (decimal, or 0x/0o/0b, '_' between digits).
struct Integer {
  bool negative = false;
  uint64_t magnitude = 0;
};

std::optional<Integer> parse_integer(std::string_view text) {
  std::string_view s = trim(text);
  Integer value;
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) {
    value.negative = s[0] == '-';
    s.remove_prefix(1);
  }
  int base = 10;
  if (s.size() > 2 && s[0] == '0') {
    const char prefix = static_cast<char>(s[1] | 0x20);
    base = prefix == 'x' ? 16 : prefix == 'o' ? 8 : prefix == 'b' ? 2 : 10;
    if (base != 10) s.remove_prefix(2);
  }
  if (s.empty() || s.front() == '_' || s.back() == '_') return std::nullopt;
  char previous = 0;
  for (char c : s) {
    if (c == '_' && previous == '_') return std::nullopt;
    previous = c;
    if (c == '_') continue;
    const char lower = static_cast<char>(c | 0x20);
    const int digit = is_digit(c) ? c - '0' : lower >= 'a' && lower <= 'f' ? lower - 'a' + 10 : 99;
    if (digit >= base) return std::nullopt;
    if (value.magnitude > (std::numeric_limits<uint64_t>::max() - digit) / base)
      return std::nullopt;
    value.magnitude = value.magnitude * base + digit;
  }
  return value;
}

std::string integer_text(const Integer& value) {
  return (value.negative && value.magnitude ? "-" : "") + std::to_string(value.magnitude);
}

// A floating-point number as Python's float() reads it; std::nullopt if it is not one.
std::optional<double> parse_floating(std::string_view text) {
  std::string s;
  std::string_view view = trim(text);
  for (size_t i = 0; i < view.size(); ++i) {
    if (view[i] == '_') {
      if (i == 0 || i + 1 == view.size() || !is_digit(view[i - 1]) || !is_digit(view[i + 1]))
        return std::nullopt;
      continue;
    }
    s += view[i];
  }
  if (!s.empty() && s[0] == '+') s.erase(0, 1);
  if (s.empty() || s[0] == '+') return std::nullopt;
  double value = 0;
  auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (error != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return value;
}

// Python's repr() of a float: the shortest digits that read back, fixed notation for
// exponents -4..15 ("0.5", "3.0", "1e-05", "1e+16").
std::string floating_text(double value) {
  std::array<char, 64> buffer{};
  auto [end, error] = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                    std::chars_format::scientific);
  std::string scientific(buffer.data(), end);
  std::string sign;
  if (scientific[0] == '-') {
    sign = "-";
    scientific.erase(0, 1);
  }
  const size_t e = scientific.find('e');
  std::string digits = scientific.substr(0, e);
  digits.erase(std::remove(digits.begin(), digits.end(), '.'), digits.end());
  const int exponent = std::stoi(scientific.substr(e + 1));
  if (exponent >= -4 && exponent < 16) {
    const int point = exponent + 1;  // digits before the decimal point
    std::string whole, fraction;
    if (point <= 0) {
      whole = "0";
      fraction = std::string(-point, '0') + digits;
    } else {
      if (static_cast<int>(digits.size()) < point) digits.append(point - digits.size(), '0');
      whole = digits.substr(0, point);
      fraction = digits.substr(point);
    }
    return sign + whole + "." + (fraction.empty() ? "0" : fraction);
  }
  std::string mantissa = digits.substr(0, 1);
  if (digits.size() > 1) mantissa += "." + digits.substr(1);
  std::string exponent_digits = std::to_string(std::abs(exponent));
  if (exponent_digits.size() < 2) exponent_digits.insert(0, "0");
  return sign + mantissa + "e" + (exponent < 0 ? "-" : "+") + exponent_digits;
}

void append_utf8(std::string& out, uint32_t code) {
  if (code < 0x80) {
    out += static_cast<char>(code);
  } else if (code < 0x800) {
    out += static_cast<char>(0xC0 | (code >> 6));
    out += static_cast<char>(0x80 | (code & 0x3F));
  } else if (code < 0x10000) {
    out += static_cast<char>(0xE0 | (code >> 12));
    out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (code & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (code >> 18));
    out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (code & 0x3F));
  }
}

// rosidl reads backslash escapes in strings and comments (Python's "unicode_escape"):
// \n, \t, \\, \", \x41, \101, \u00e9 ... become the characters; an unknown escape stays.
std::string decode_escapes(std::string_view s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '\\' || i + 1 == s.size()) {
      out += s[i];
      continue;
    }
    const char c = s[++i];
    auto hex = [&](size_t count) -> std::optional<uint32_t> {
      uint32_t code = 0;
      for (size_t k = 1; k <= count; ++k) {
        if (i + k >= s.size()) return std::nullopt;
        const char h = static_cast<char>(s[i + k] | 0x20);
        if (!is_digit(s[i + k]) && !(h >= 'a' && h <= 'f')) return std::nullopt;
        code = code * 16 + (is_digit(s[i + k]) ? s[i + k] - '0' : h - 'a' + 10);
      }
      i += count;
      return code;
    };
    switch (c) {
      case '\n':
        break;
      case '\\':
        out += '\\';
        break;
      case '\'':
        out += '\'';
        break;
      case '"':
        out += '"';
        break;
      case 'a':
        out += '\a';
        break;
      case 'b':
        out += '\b';
        break;
      case 'f':
        out += '\f';
        break;
      case 'n':
        out += '\n';
        break;
      case 'r':
        out += '\r';
        break;
      case 't':
        out += '\t';
        break;
      case 'v':
        out += '\v';
        break;
      case 'x':
      case 'u':
      case 'U': {
        const size_t count = c == 'x' ? 2 : c == 'u' ? 4 : 8;
        if (auto code = hex(count)) {
          if (c == 'x')
            out += static_cast<char>(*code);
          else
            append_utf8(out, *code);
        } else {
          out += '\\';
          out += c;
        }
        break;
      }
      default:
        if (c >= '0' && c <= '7') {
          uint32_t code = c - '0';
          for (int k = 0; k < 2 && i + 1 < s.size() && s[i + 1] >= '0' && s[i + 1] <= '7'; ++k)
            code = code * 8 + (s[++i] - '0');
          out += static_cast<char>(code & 0xFF);
        } else {
          out += '\\';
          out += c;
        }
    }
  }
  return out;
}

// An IDL string literal that both fastddsgen 2.3 and Foxglove's IDL parser read: they share
// the escapes \\, \n and \r, but fastddsgen reads no \" and Foxglove no octal or \t. So a
// value with a double quote or another control character is refused (`fail`); in comments,
// which are not data, a double quote becomes a single one and a control character a space.
std::string idl_string_literal(std::string_view s, const Failure* fail) {
  std::string out = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '"' || u < 0x20 || u == 0x7F) {
      if (fail)
        (*fail)(std::string("string value with ") +
                (c == '"' ? "a double quote" : "a control character") +
                ": IDL cannot carry it to both fastddsgen 2.3 and Foxglove's parser (write it "
                "without)");
      out += c == '"' ? '\'' : ' ';
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// Python's repr() of a str, for array defaults: single quotes unless the text holds one.
std::string python_string_repr(std::string_view s) {
  const bool has_single = s.find('\'') != std::string_view::npos;
  const bool has_double = s.find('"') != std::string_view::npos;
  const char quote = has_single && !has_double ? '"' : '\'';
  std::string out(1, quote);
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == quote || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (u < 0x20 || u == 0x7F) {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[u >> 4];
      out += hex[u & 15];
    } else {
      out += c;
    }
  }
  return out + quote;
}

using Value = std::variant<bool, Integer, double, std::string>;

// One primitive value, checked against its type (rosidl's parse_primitive_value_string).
Value parse_primitive(const MsgType& type, std::string_view text, const Failure& fail) {
  const std::string& name = type.name;
  const std::string quoted = "'" + std::string(text) + "'";
  if (name == "bool") {
    std::string lower(trim(text));
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](char c) { return static_cast<char>(c | (is_upper(c) ? 0x20 : 0)); });
    if (lower == "true" || lower == "1") return true;
    if (lower == "false" || lower == "0") return false;
    fail("value " + quoted + " is not a bool: write true / 1 or false / 0");
  }
  if (name == "byte" || name == "char" || (name.find("int") != std::string::npos)) {
    const bool is_unsigned = name == "byte" || name == "char" || name[0] == 'u';
    const int bits =
        name == "byte" || name == "char" ? 8 : std::stoi(name.substr(is_unsigned ? 4 : 3));
    const uint64_t high = is_unsigned ? std::numeric_limits<uint64_t>::max() >> (64 - bits)
                                      : (uint64_t{1} << (bits - 1)) - 1;
    const Integer low{!is_unsigned, is_unsigned ? 0 : high + 1};
    auto value = parse_integer(text);
    const bool in_range = value && (value->negative && value->magnitude
                                        ? value->magnitude <= low.magnitude && !is_unsigned
                                        : value->magnitude <= high);
    if (!in_range)
      fail("value " + quoted + " is not a " + name + ": an integer from " + integer_text(low) +
           " to " + std::to_string(high));
    return *value;
  }
  if (name == "float32" || name == "float64") {
    auto value = parse_floating(text);
    if (!value) fail("value " + quoted + " is not a " + name + ": a number with '.' as separator");
    if (!std::isfinite(*value))
      fail("value " + quoted + " is not finite: IDL has no literal for it");
    return *value;
  }
  // string, wstring: outer quotes allow leading and trailing spaces; inner ones are escaped.
  std::string value(text);
  for (char quote : {'"', '\''}) {
    if (value.size() >= 2 && value.front() == quote && value.back() == quote) {
      value = value.substr(1, value.size() - 2);
      for (size_t i = 0; i < value.size(); ++i)
        if (value[i] == quote && (i == 0 || value[i - 1] != '\\'))
          fail("value " + quoted + ": a " + std::string(1, quote) +
               " inside the quotes must be escaped");
      std::string unescaped;
      for (size_t i = 0; i < value.size(); ++i) {
        if (value[i] == '\\' && i + 1 < value.size() && value[i + 1] == quote) continue;
        unescaped += value[i];
      }
      value = unescaped;
      break;
    }
  }
  if (type.string_bound && value.size() > *type.string_bound)
    fail("value " + quoted + " is longer than the bound of " + std::to_string(*type.string_bound) +
         " characters");
  return value;
}

std::string idl_literal(const Value& value, const Failure& fail) {
  if (auto b = std::get_if<bool>(&value)) return *b ? "TRUE" : "FALSE";
  if (auto i = std::get_if<Integer>(&value)) return integer_text(*i);
  if (auto d = std::get_if<double>(&value)) return floating_text(*d);
  return idl_string_literal(decode_escapes(std::get<std::string>(value)), &fail);
}

std::string python_repr(const Value& value) {
  if (auto b = std::get_if<bool>(&value)) return *b ? "True" : "False";
  if (auto i = std::get_if<Integer>(&value)) return integer_text(*i);
  if (auto d = std::get_if<double>(&value)) return floating_text(*d);
  return python_string_repr(std::get<std::string>(value));
}

// The elements of a string array's default: quoted ('a', "b, c") or bare up to the next comma.
std::vector<std::string> split_string_elements(std::string_view text, const Failure& fail) {
  std::vector<std::string> elements;
  while (!(text = ltrim(text)).empty()) {
    if (text[0] == ',') fail("unexpected ',' in the string array '[" + std::string(text) + "]'");
    if (text[0] == '"' || text[0] == '\'') {
      const char quote = text[0];
      size_t end = 1;
      while (end < text.size() && (text[end] != quote || text[end - 1] == '\\')) ++end;
      if (end == text.size()) fail("string '" + std::string(text) + "' has no closing quote");
      std::string element;
      for (size_t i = 1; i < end; ++i) {
        if (text[i] == '\\' && i + 1 < end && text[i + 1] == quote) continue;
        element += text[i];
      }
      elements.push_back(element);
      text.remove_prefix(end + 1);
    } else {
      const size_t comma = text.find(',');
      elements.emplace_back(text.substr(0, comma));
      text = comma == std::string_view::npos ? std::string_view() : text.substr(comma);
    }
    text = ltrim(text);
    if (!text.empty() && text[0] == ',') text.remove_prefix(1);
  }
  return elements;
}

std::string type_text(const MsgType& type) {
  std::string s = type.is_primitive() ? type.name : type.package + "/" + type.name;
  if (type.string_bound) s += "<=" + std::to_string(*type.string_bound);
  if (type.is_array) {
    s += "[";
    if (type.array_is_bound) s += "<=";
    if (type.array_size) s += std::to_string(*type.array_size);
    s += "]";
  }
  return s;
}

// A default value as rosidl writes it: a literal, or for arrays the string of Python's tuple
// repr ("(1.0, 2.0)").
std::string parse_default(const MsgType& type, std::string_view text, const Failure& fail) {
  if (!type.is_primitive())
    fail("field of type " + type_text(type) + " cannot have a default value: only primitives can");
  if (!type.is_array) return idl_literal(parse_primitive(type, text, fail), fail);
  if (text.empty() || text.front() != '[' || text.back() != ']')
    fail("default '" + std::string(text) + "' of the array " + type_text(type) +
         " must start with '[' and end with ']'");
  const std::string_view inner = text.substr(1, text.size() - 2);
  std::vector<std::string> elements;
  if (type.name == "string" || type.name == "wstring") {
    elements = split_string_elements(inner, fail);
  } else if (!inner.empty()) {
    std::string_view rest = inner;
    for (size_t comma; (comma = rest.find(',')) != std::string_view::npos;
         rest.remove_prefix(comma + 1))
      elements.emplace_back(rest.substr(0, comma));
    elements.emplace_back(rest);
  }
  if (type.array_size && !type.array_is_bound && elements.size() != *type.array_size)
    fail("default of " + type_text(type) + " has " + std::to_string(elements.size()) +
         " elements, not " + std::to_string(*type.array_size));
  if (type.array_size && type.array_is_bound && elements.size() > *type.array_size)
    fail("default of " + type_text(type) + " has " + std::to_string(elements.size()) +
         " elements, more than " + std::to_string(*type.array_size));
  MsgType element_type = type;
  element_type.is_array = false;
  std::string tuple = "(";
  for (size_t i = 0; i < elements.size(); ++i) {
    if (i > 0) tuple += ", ";
    tuple += python_repr(parse_primitive(element_type, trim(elements[i]), fail));
  }
  tuple += elements.size() == 1 ? ",)" : ")";
  return idl_string_literal(tuple, &fail);
}

std::optional<uint64_t> positive_size(std::string_view text) {
  auto value = parse_integer(text);
  if (!value || value->negative || value->magnitude == 0 ||
      value->magnitude > std::numeric_limits<uint32_t>::max())
    return std::nullopt;
  return value->magnitude;
}

MsgType parse_type(std::string_view text, std::string_view package, const Failure& fail) {
  MsgType type;
  if (!text.empty() && text.back() == ']') {
    const size_t open = text.rfind('[');
    if (open == std::string_view::npos)
      fail("type '" + std::string(text) + "' ends with ']' but has no '['");
    std::string_view size = text.substr(open + 1, text.size() - open - 2);
    type.is_array = true;
    if (!size.empty()) {
      type.array_is_bound = starts_with(size, "<=");
      if (type.array_is_bound) size.remove_prefix(2);
      type.array_size = positive_size(size);
      if (!type.array_size)
        fail("the size of the array type '" + std::string(text) +
             "' must be an integer > 0, with '<=' before it for an upper bound");
    }
    text = text.substr(0, open);
  }
  if (text == "time" || text == "duration")
    fail("type '" + std::string(text) + "' is ROS 1's: write builtin_interfaces/" +
         (text == "time" ? "Time" : "Duration"));
  if (kIdlPrimitive.count(text)) {
    type.name = text;
    return type;
  }
  for (std::string_view bounded : {"string<=", "wstring<="}) {
    if (starts_with(text, bounded)) {
      type.name = text.substr(0, bounded.size() - 2);
      type.string_bound = positive_size(text.substr(bounded.size()));
      if (!type.string_bound)
        fail("the bound of the string type '" + std::string(text) + "' must be an integer > 0");
      return type;
    }
  }
  const size_t slash = text.find('/');
  if (slash == std::string_view::npos) {
    type.package = package;
    type.name = text;
  } else {
    type.package = text.substr(0, slash);
    type.name = text.substr(slash + 1);
    if (type.name.find('/') != std::string::npos)
      fail("type '" + std::string(text) + "': a .msg file names a message as <package>/<Type> " +
           "(geometry_msgs/Pose), without /msg/");
  }
  if (!valid_package_or_field_name(type.package))
    fail("'" + type.package + "' in type '" + std::string(text) +
         "' is not a package name: lower case, digits and single underscores");
  if (!valid_message_name(type.name))
    fail("'" + std::string(text) +
         "' is not a type: a primitive (bool, int32, float64, string, ...)" +
         " or a message, <package>/<Type> with Type in CamelCase");
  return type;
}

// rosidl's process_comments: a single "[unit]" becomes the unit; blank lines at either end are
// dropped, runs of them become one, and the common indent is removed.
void tidy_comment(std::vector<std::string>& lines, std::optional<std::string>* unit) {
  std::string joined;
  for (size_t i = 0; i < lines.size(); ++i) joined += (i ? "\n" : "") + lines[i];
  std::vector<std::pair<size_t, size_t>> matches;  // [begin, end) of "\s*[text]"
  size_t search_from = 0;
  for (size_t open = joined.find('['); open != std::string::npos;
       open = joined.find('[', open + 1)) {
    size_t close = open + 1;
    while (close < joined.size() && joined[close] != ',' && joined[close] != ']') ++close;
    if (close == joined.size() || joined[close] != ']' || close == open + 1) continue;
    size_t begin = open;
    while (begin > search_from && is_space(joined[begin - 1])) --begin;
    matches.emplace_back(begin, close + 1);
    search_from = close + 1;
    open = close;
  }
  if (matches.size() == 1) {
    const std::string text = joined.substr(matches[0].first, matches[0].second - matches[0].first);
    const size_t open = text.find('[');
    if (unit) *unit = text.substr(open + 1, text.size() - open - 2);
    for (auto& line : lines)
      for (size_t at; (at = line.find(text)) != std::string::npos;) line.erase(at, text.size());
  }
  while (!lines.empty() && lines.front().empty()) lines.erase(lines.begin());
  while (!lines.empty() && lines.back().empty()) lines.pop_back();
  for (size_t i = 1; i < lines.size();) {
    if (lines[i].empty() && lines[i - 1].empty())
      lines.erase(lines.begin() + i);
    else
      ++i;
  }
  size_t indent = std::string::npos;
  for (auto& line : lines) {
    if (trim(line).empty()) {
      line.clear();
      continue;
    }
    indent = std::min(indent, line.find_first_not_of(" \t"));
  }
  if (indent == std::string::npos) return;
  for (auto& line : lines)
    if (!line.empty()) line.erase(0, indent);
}

std::string strip_hashes(std::string_view s) {
  while (!s.empty() && s.front() == '#') s.remove_prefix(1);
  return std::string(s);
}

std::string idl_type(const MsgType& type) {
  std::string base = type.is_primitive() ? kIdlPrimitive.find(type.name)->second
                                         : type.package + "::msg::" + type.name;
  if (type.string_bound) base += "<" + std::to_string(*type.string_bound) + ">";
  if (!type.is_array) return base;
  if (type.is_fixed_array()) return base + "[" + std::to_string(*type.array_size) + "]";
  // "sequence<string<8> >": fastddsgen 2.3 reads ">>" as one token (rosidl writes ">>").
  if (!type.array_is_bound) return "sequence<" + base + (base.back() == '>' ? " >" : ">");
  return "sequence<" + base + ", " + std::to_string(*type.array_size) + ">";
}

// rosidl's name for a fixed array's typedef: double[36] -> double__36.
std::string typedef_identifier(std::string s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s.compare(i, 2, "::") == 0) {
      out += "__";
      ++i;
    } else if (s[i] == '<' || s[i] == '[') {
      out += "__";
    } else if (s[i] != '>' && s[i] != ']') {
      out += s[i];
    }
  }
  return out;
}

void write_verbatim(std::ostringstream& out, const std::vector<std::string>& comment,
                    const std::string& indent) {
  if (comment.empty()) return;
  out << indent << "@verbatim (language=\"comment\", text=";
  for (size_t i = 0; i < comment.size(); ++i) {
    out << "\n" << indent << "  " << idl_string_literal(decode_escapes(comment[i]), nullptr);
    if (i + 1 < comment.size()) out << " \"\\n\"";
  }
  out << ")\n";
}

// The lines of a .msg file, tabs as spaces.
std::vector<std::string> split_lines(std::string_view text) {
  std::vector<std::string> lines;
  for (size_t start = 0; start <= text.size();) {
    size_t end = text.find_first_of("\r\n", start);
    if (end == std::string_view::npos) end = text.size();
    std::string line(text.substr(start, end - start));
    std::replace(line.begin(), line.end(), '\t', ' ');
    if (end == text.size() && line.empty()) break;
    lines.push_back(line);
    start = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
  }
  return lines;
}

// "<type> <NAME>=<value>": `rest` is what follows the type, `equals` where its '=' is.
MsgConstant parse_constant(const MsgSpecification& msg, std::string_view type_string,
                           std::string_view rest, size_t equals, int line_number,
                           const Failure& fail) {
  const std::string_view package = msg.package;
  MsgConstant constant;
  constant.line = line_number;
  constant.name = rtrim(rest.substr(0, equals));
  if (!kIdlPrimitive.count(type_string))
    fail("constant " + constant.name + " has type '" + std::string(type_string) +
         "': constants are unbounded primitives (bool, int32, float64, string, ...)");
  if (!valid_constant_name(constant.name))
    fail("'" + constant.name +
         "' is not a constant name: upper case, digits and single underscores");
  for (const auto& other : msg.constants)
    if (other.name == constant.name) fail("constant " + constant.name + " is defined twice");
  constant.type = parse_type(type_string, package, fail);
  constant.value_idl =
      idl_literal(parse_primitive(constant.type, ltrim(rest.substr(equals + 1)), fail), fail);
  return constant;
}

// "<type> <name> [default]": `rest` is what follows the type.
MsgField parse_field(const MsgSpecification& msg, std::string_view type_string,
                     std::string_view rest, int line_number, const Failure& fail) {
  const std::string_view package = msg.package;
  MsgField field;
  field.line = line_number;
  const size_t name_end = rest.find(' ');
  field.name = rest.substr(0, name_end);
  field.type = parse_type(type_string, package, fail);
  if (field.type.is_fixed_array() && field.type.is_primitive() &&
      (field.type.name == "string" || field.type.name == "wstring"))
    fail("fixed array of strings '" + std::string(type_string) +
         "': fastddsgen 2.3 writes them but does not read them back; use " +
         type_text(MsgType{field.type.package, field.type.name, field.type.string_bound, true,
                           field.type.array_size, true}) +
         " (at most N) instead");
  if (!valid_package_or_field_name(field.name))
    fail("'" + field.name + "' is not a field name: lower case, digits and single underscores");
  for (const auto& other : msg.fields)
    if (other.name == field.name) fail("field " + field.name + " is defined twice");
  if (name_end != std::string_view::npos) {
    const std::string_view default_text = ltrim(rest.substr(name_end + 1));
    if (!default_text.empty()) field.default_idl = parse_default(field.type, default_text, fail);
  }
  return field;
}

}  // namespace

MsgSpecification parse_msg(std::string_view package, std::string_view name, std::string_view text,
                           std::string_view file) {
  if (!valid_package_or_field_name(package))
    Failure(file, 0)("package name '" + std::string(package) +
                     "' is not lower case, digits and single underscores");
  if (!valid_message_name(name))
    Failure(file, 0)("message name '" + std::string(name) + "' is not CamelCase");
  MsgSpecification msg;
  msg.package = package;
  msg.name = name;

  const std::vector<std::string> lines = split_lines(text);

  size_t first = 0;  // the comment block at the top documents the message
  while (first < lines.size() && starts_with(lines[first], "#"))
    msg.comment.push_back(strip_hashes(lines[first++]));

  std::vector<std::string> pending_comment;
  std::vector<std::string>* last_comment = nullptr;  // valid until the next push_back
  for (size_t index = first; index < lines.size(); ++index) {
    const int line_number = static_cast<int>(index + 1);
    const Failure fail(file, line_number);
    std::string_view line = rtrim(lines[index]);
    if (line.empty()) continue;
    const size_t hash = line.find('#');
    if (hash != std::string_view::npos) {
      const std::string comment = strip_hashes(line.substr(hash));
      line = line.substr(0, hash);
      if (!line.empty() && trim(line).empty()) {  // an indented comment continues the last line's
        if (last_comment) last_comment->push_back(comment);
        continue;
      }
      pending_comment.push_back(comment);
      line = rtrim(line);
      if (line.empty()) continue;
    }
    const size_t space = line.find(' ');
    const std::string_view type_string = line.substr(0, space);
    const std::string_view rest =
        space == std::string_view::npos ? std::string_view() : ltrim(line.substr(space + 1));
    if (rest.empty())
      fail("'" + std::string(line) + "' is not '<type> <name>' nor '<type> <NAME>=<value>'");

    const size_t equals = rest.find('=');
    if (equals != std::string_view::npos) {
      msg.constants.push_back(parse_constant(msg, type_string, rest, equals, line_number, fail));
      last_comment = &msg.constants.back().comment;
    } else {
      msg.fields.push_back(parse_field(msg, type_string, rest, line_number, fail));
      last_comment = &msg.fields.back().comment;
    }
    last_comment->insert(last_comment->end(), pending_comment.begin(), pending_comment.end());
    pending_comment.clear();
  }
  tidy_comment(msg.comment, nullptr);
  for (auto& field : msg.fields) tidy_comment(field.comment, &field.unit);
  for (auto& constant : msg.constants) tidy_comment(constant.comment, nullptr);
  return msg;
}

std::vector<std::string> msg_includes(const MsgSpecification& msg) {
  std::set<std::string> includes;
  for (const auto& field : msg.fields)
    if (!field.type.is_primitive())
      includes.insert(field.type.package + "/msg/" + field.type.name + ".idl");
  return {includes.begin(), includes.end()};
}

std::string msg_to_idl(const MsgSpecification& msg, std::string_view source) {
  std::ostringstream out;
  out << "// generated by mocap_msg_to_idl from " << source
      << " as ROS 2's rosidl_adapter converts it\n"
      << "// do not edit: change the .msg file\n\n";
  for (const auto& include : msg_includes(msg)) out << "#include \"" << include << "\"\n";
  out << "\nmodule " << msg.package << " {\n  module msg {\n";

  std::vector<std::pair<std::string, std::string>> typedefs;  // name[N] -> base, in order
  auto add_typedef = [&](const std::string& name, const std::string& base) {
    for (const auto& [existing, _] : typedefs)
      if (existing == name) return;
    typedefs.emplace_back(name, base);
  };
  for (const auto& field : msg.fields) {
    if (!field.type.is_fixed_array()) continue;
    const std::string type = idl_type(field.type);
    const std::string base = type.substr(0, type.find('['));
    std::string base_identifier = base;
    for (size_t at; (at = base_identifier.find("::")) != std::string::npos;)
      base_identifier.replace(at, 2, "__");
    if (base_identifier != base) add_typedef(base_identifier, base);
    add_typedef(typedef_identifier(type) + "[" + std::to_string(*field.type.array_size) + "]",
                base_identifier);
  }
  for (const auto& [name, base] : typedefs) out << "    typedef " << base << " " << name << ";\n";

  if (!msg.constants.empty()) {
    out << "    module " << msg.name << "_Constants {\n";
    for (const auto& constant : msg.constants) {
      write_verbatim(out, constant.comment, "      ");
      out << "      const " << idl_type(constant.type) << " " << constant.name << " = "
          << constant.value_idl << ";\n";
    }
    out << "    };\n";
  }
  write_verbatim(out, msg.comment, "    ");
  out << "    struct " << msg.name << " {\n";
  for (size_t i = 0; i < msg.fields.size(); ++i) {
    const MsgField& field = msg.fields[i];
    if (i > 0) out << "\n";
    write_verbatim(out, field.comment, "      ");
    if (field.default_idl) out << "      @default (value=" << *field.default_idl << ")\n";
    if (field.unit)
      out << "      @unit (value=" << idl_string_literal(decode_escapes(*field.unit), nullptr)
          << ")\n";
    const std::string type = idl_type(field.type);
    out << "      " << (field.type.is_fixed_array() ? typedef_identifier(type) : type) << " "
        << field.name << ";\n";
  }
  if (msg.fields.empty()) out << "      uint8 structure_needs_at_least_one_member;\n";
  out << "    };\n  };\n};\n";
  return out.str();
}

}  // namespace mocap
