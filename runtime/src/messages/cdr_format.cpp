#include "messages/cdr_format.hpp"

#include <bit>
#include <cstring>

#include <fmt/format.h>

#include <mocap/message_type.hpp>

namespace mocap {
namespace {

size_t primitive_size(IdlKind kind) {
  switch (kind) {
    case IdlKind::Bool:
    case IdlKind::Char:
    case IdlKind::Octet:
    case IdlKind::Int8:
    case IdlKind::UInt8:
      return 1;
    case IdlKind::Int16:
    case IdlKind::UInt16:
      return 2;
    case IdlKind::Int32:
    case IdlKind::UInt32:
    case IdlKind::Float:
    case IdlKind::Enum:
      return 4;
    case IdlKind::Int64:
    case IdlKind::UInt64:
    case IdlKind::Double:
      return 8;
    default:
      return 0;  // not fixed-size
  }
}

// Reads XCDR1: primitives aligned to their size, counted from the end of the 4-byte header.
class Cursor {
 public:
  explicit Cursor(std::span<const uint8_t> data) : data_(data) {
    if (data.size() < 4) throw SerializationError("shorter than the 4-byte encapsulation header");
    if (data[0] != 0 || data[1] > 1) {
      throw SerializationError(
          fmt::format("encapsulation {:02x}{:02x} is not plain CDR (only XCDR1 data can be shown)",
                      data[0], data[1]));
    }
    little_ = data[1] == 1;
  }

  template <class T>
  T read() {
    align(sizeof(T));
    need(sizeof(T));
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    if (little_ != (std::endian::native == std::endian::little) && sizeof(T) > 1) {
      auto* bytes = reinterpret_cast<uint8_t*>(&value);
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
    }
    return value;
  }

  uint32_t length() {
    uint32_t n = read<uint32_t>();
    if (n > data_.size()) throw SerializationError(fmt::format("length {} exceeds the data", n));
    return n;
  }

  std::string string() {
    uint32_t n = length();
    need(n);
    std::string text(reinterpret_cast<const char*>(data_.data() + pos_), n > 0 ? n - 1 : 0);
    pos_ += n;
    return text;
  }

  void skip(size_t element_size, size_t count) {
    align(element_size);
    need(element_size * count);
    pos_ += element_size * count;
  }

 private:
  void align(size_t n) { pos_ = 4 + (pos_ - 4 + n - 1) / n * n; }
  void need(size_t n) const {
    if (pos_ + n > data_.size()) {
      throw SerializationError(
          fmt::format("data ends at byte {}, {} more needed at byte {}", data_.size(), n, pos_));
    }
  }

  std::span<const uint8_t> data_;
  size_t pos_ = 4;
  bool little_ = true;
};

std::string quote(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

class Formatter {
 public:
  Formatter(const IdlSchema& schema, Cursor& cursor, const CdrFormatOptions& options)
      : schema_(schema), cursor_(cursor), options_(options) {}

  // One "name: value" line per member, nested structs indented below their name.
  void block(const IdlStruct& type, int indent, std::string& out) {
    Nesting nesting(depth_);
    for (const IdlMember& member : type.members) {
      std::string pad(static_cast<size_t>(indent), ' ');
      if (member.type.kind == IdlKind::Struct && member.type.array.empty()) {
        out += pad + member.name + ":\n";
        block(structure(member.type.name), indent + 2, out);
      } else if (is_struct_list(member.type)) {
        size_t count = element_count(member.type);
        if (count == 0) {
          out += pad + member.name + ": []\n";
          continue;
        }
        out += pad + member.name + ":\n";
        const IdlStruct& element = structure(element_type(member.type).name);
        for (size_t i = 0; i < count; ++i) {
          std::string item;
          block(element, indent + 4, item);
          // "- " takes the place of the first field's indentation.
          if (item.size() >= static_cast<size_t>(indent + 4)) {
            item.replace(0, static_cast<size_t>(indent + 4), pad + "  - ");
          }
          out += item.empty() ? pad + "  - {}\n" : item;
        }
      } else {
        out += pad + member.name + ": " + inline_value(member.type) + "\n";
      }
    }
  }

 private:
  const IdlStruct& structure(const std::string& name) const {
    const IdlStruct* found = schema_.find(name);
    if (found == nullptr) throw IdlError(fmt::format("type {} has no IDL definition", name));
    return *found;
  }

  static IdlType element_type(const IdlType& type) {
    if (!type.array.empty()) {
      IdlType element = type;
      element.array.clear();
      return element;
    }
    return *type.element;
  }

  static bool is_struct_list(const IdlType& type) {
    if (!type.array.empty()) return type.kind == IdlKind::Struct;
    return type.kind == IdlKind::Sequence && type.element->kind == IdlKind::Struct &&
           type.element->array.empty();
  }

  // Reads the length of a sequence, or computes that of an array.
  size_t element_count(const IdlType& type) {
    if (!type.array.empty()) {
      uint64_t count = 1;
      for (uint32_t d : type.array) {
        count *= d;
        if (count > (uint64_t(1) << 32)) throw IdlError("an array with more than 2^32 elements");
      }
      return static_cast<size_t>(count);
    }
    return cursor_.length();
  }

  // Counts struct nesting: a struct that contains itself would recurse without end.
  class Nesting {
   public:
    explicit Nesting(int& depth) : depth_(depth) {
      if (++depth_ > kMaxNesting) throw IdlError("structs nested deeper than 100 levels");
    }
    ~Nesting() { --depth_; }

   private:
    static constexpr int kMaxNesting = 100;
    int& depth_;
  };

  std::string inline_value(const IdlType& type) {
    if (!type.array.empty() || type.kind == IdlKind::Sequence) {
      size_t count = element_count(type);
      IdlType element = element_type(type);
      std::string out = "[";
      size_t shown = std::min(count, options_.max_items);
      for (size_t i = 0; i < shown; ++i) out += (i ? ", " : "") + inline_value(element);
      if (shown < count) {
        size_t fixed = element.array.empty() ? primitive_size(element.kind) : 0;
        if (fixed > 0) {
          cursor_.skip(fixed, count - shown);
        } else {
          for (size_t i = shown; i < count; ++i) inline_value(element);
        }
        out += fmt::format(", ...] # {} items", count);
        return out;
      }
      return out + "]";
    }
    switch (type.kind) {
      case IdlKind::Bool:
        return cursor_.read<uint8_t>() ? "true" : "false";
      case IdlKind::Char:
        return quote(std::string(1, static_cast<char>(cursor_.read<uint8_t>())));
      case IdlKind::Octet:
      case IdlKind::UInt8:
        return fmt::format("{}", cursor_.read<uint8_t>());
      case IdlKind::Int8:
        return fmt::format("{}", cursor_.read<int8_t>());
      case IdlKind::Int16:
        return fmt::format("{}", cursor_.read<int16_t>());
      case IdlKind::UInt16:
        return fmt::format("{}", cursor_.read<uint16_t>());
      case IdlKind::Int32:
        return fmt::format("{}", cursor_.read<int32_t>());
      case IdlKind::UInt32:
      case IdlKind::Enum:
        return fmt::format("{}", cursor_.read<uint32_t>());
      case IdlKind::Int64:
        return fmt::format("{}", cursor_.read<int64_t>());
      case IdlKind::UInt64:
        return fmt::format("{}", cursor_.read<uint64_t>());
      case IdlKind::Float:
        return fmt::format("{}", cursor_.read<float>());
      case IdlKind::Double:
        return fmt::format("{}", cursor_.read<double>());
      case IdlKind::String:
        return quote(cursor_.string());
      case IdlKind::Struct: {
        Nesting nesting(depth_);
        const IdlStruct& s = structure(type.name);
        std::string out = "{";
        for (size_t i = 0; i < s.members.size(); ++i) {
          out += (i ? ", " : "") + s.members[i].name + ": " + inline_value(s.members[i].type);
        }
        return out + "}";
      }
      case IdlKind::Sequence:
        break;  // handled above
    }
    return "?";
  }

  const IdlSchema& schema_;
  Cursor& cursor_;
  const CdrFormatOptions& options_;
  int depth_ = 0;
};

}  // namespace

std::string format_cdr(const IdlSchema& schema, std::string_view type,
                       std::span<const uint8_t> data, const CdrFormatOptions& options) {
  const IdlStruct* root = schema.find(type);
  if (root == nullptr) throw IdlError(fmt::format("type {} has no IDL definition", type));
  Cursor cursor(data);
  std::string out;
  Formatter(schema, cursor, options).block(*root, 0, out);
  return out;
}

}  // namespace mocap
