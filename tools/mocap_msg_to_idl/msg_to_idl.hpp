// ROS 2 .msg files read and written as IDL, the way ROS 2's rosidl_adapter converts them, so
// that a message package written for ROS 2 builds here unchanged (mocap_generate_messages).
//
// The .msg grammar is ROS 2's: one field per line, "type name [default]"; constants as
// "type NAME=value"; '#' comments, kept as @verbatim annotations, a "[unit]" in a field's
// comment as @unit; types are the primitives, pkg/Type or Type (this package), with "[]",
// "[N]" or "[<=N]" for arrays and "string<=N" for bounded strings. The IDL is rosidl_adapter's:
// the same typedef names for fixed arrays (double__36), a <Type>_Constants module, @default
// annotations, one include per message type used.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace mocap {

// A .msg file that cannot be converted. what() is "<file>:<line>: <reason>" (line 0: the
// whole file).
class MsgError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct MsgType {
  std::string package;  // empty for a primitive
  std::string name;     // the primitive ("float64", "string") or the message ("Pose")
  std::optional<uint64_t> string_bound;  // string<=N, wstring<=N
  bool is_array = false;
  std::optional<uint64_t> array_size;  // [N] or [<=N]
  bool array_is_bound = false;         // [<=N]

  bool is_primitive() const { return package.empty(); }
  bool is_fixed_array() const { return is_array && array_size && !array_is_bound; }
};

struct MsgField {
  MsgType type;
  std::string name;
  std::optional<std::string> default_idl;  // the default as an IDL literal
  std::vector<std::string> comment;
  std::optional<std::string> unit;
  int line = 0;
};

struct MsgConstant {
  MsgType type;
  std::string name;
  std::string value_idl;  // the value as an IDL literal
  std::vector<std::string> comment;
  int line = 0;
};

struct MsgSpecification {
  std::string package;
  std::string name;
  std::vector<std::string> comment;
  std::vector<MsgConstant> constants;
  std::vector<MsgField> fields;
};

// Parses the text of <package>/msg/<name>.msg. `file` names it in errors. Throws MsgError for
// what rosidl refuses, and for a string value with a double quote or a control character other
// than a newline: no IDL string can carry those to both fastddsgen 2.3 and Foxglove's parser.
MsgSpecification parse_msg(std::string_view package, std::string_view name, std::string_view text,
                           std::string_view file);

// The IDL of `msg` as rosidl_adapter writes it; `source` (e.g. "my_msgs/msg/Thing.msg") goes into
// the first comment line. In comments a double quote becomes a single one, for that reason.
std::string msg_to_idl(const MsgSpecification& msg, std::string_view source);

// The IDL files `msg` includes ("geometry_msgs/msg/Pose.idl"), sorted, each once.
std::vector<std::string> msg_includes(const MsgSpecification& msg);

}  // namespace mocap
