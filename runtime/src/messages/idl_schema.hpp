// The structure of message types, read from their IDL text.
//
// Covers what ROS 2 and our idl/ files use: modules, structs, typedefs, enums, constants
// (skipped), primitive types, strings, sequences and arrays. Enough to walk any such type's
// CDR without generated code.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace mocap {

class IdlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class IdlKind {
  Bool,
  Char,
  Octet,
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Int64,
  UInt64,
  Float,
  Double,
  String,
  Sequence,
  Struct,
  Enum,
};

struct IdlType {
  IdlKind kind = IdlKind::Int32;
  std::string name;                        // Struct and Enum: fully qualified ("a::msg::T")
  std::shared_ptr<const IdlType> element;  // Sequence
  std::vector<uint32_t> array;             // dimensions when the member is an array
};

struct IdlMember {
  std::string name;
  IdlType type;
};

struct IdlStruct {
  std::string name;  // fully qualified
  std::vector<IdlMember> members;
};

class IdlSchema {
 public:
  // Adds the definitions in `text`. Throws IdlError naming the line.
  void parse(std::string_view text);
  // Looks up "a::msg::T" or "a/msg/T".
  const IdlStruct* find(std::string_view name) const;

 private:
  friend class IdlParser;
  std::map<std::string, IdlStruct, std::less<>> structs_;
  std::map<std::string, IdlType, std::less<>> typedefs_;
  std::map<std::string, int, std::less<>> enums_;
};

}  // namespace mocap
