#include "messages/idl_schema.hpp"

#include <cctype>
#include <charconv>

#include <fmt/format.h>

namespace mocap {
namespace {

struct Token {
  std::string text;  // identifiers, numbers, punctuation ("::" is one token)
  int line;
};

std::vector<Token> tokenize(std::string_view text) {
  std::vector<Token> tokens;
  int line = 1;
  size_t i = 0;
  auto at_line_start = [&](size_t pos) {
    while (pos > 0 && (text[pos - 1] == ' ' || text[pos - 1] == '\t')) --pos;
    return pos == 0 || text[pos - 1] == '\n';
  };
  while (i < text.size()) {
    char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (at_line_start(i) &&
               (c == '#' || text.substr(i, 5) == "IDL: " || text.substr(i, 8) == "========")) {
      // Preprocessor lines, and the separators of ROS 2's concatenated "ros2idl" definitions.
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (text.substr(i, 2) == "//") {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (text.substr(i, 2) == "/*") {
      size_t end = text.find("*/", i + 2);
      if (end == std::string_view::npos)
        throw IdlError(fmt::format("line {}: unclosed comment", line));
      for (size_t k = i; k < end; ++k) line += text[k] == '\n';
      i = end + 2;
    } else if (c == '"') {  // string literal (in annotations and constants)
      size_t j = i + 1;
      while (j < text.size() && text[j] != '"') j += text[j] == '\\' ? 2 : 1;
      tokens.push_back({std::string(text.substr(i, j + 1 - i)), line});
      i = j + 1;
    } else if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.') {
      size_t j = i;
      while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) ||
                                 text[j] == '_' || text[j] == '.')) {
        ++j;
      }
      tokens.push_back({std::string(text.substr(i, j - i)), line});
      i = j;
    } else if (text.substr(i, 2) == "::") {
      tokens.push_back({"::", line});
      i += 2;
    } else {
      tokens.push_back({std::string(1, c), line});
      ++i;
    }
  }
  return tokens;
}

const std::map<std::string, IdlKind, std::less<>>& primitive_names() {
  static const std::map<std::string, IdlKind, std::less<>> names = {
      {"boolean", IdlKind::Bool},
      {"char", IdlKind::Char},
      {"octet", IdlKind::Octet},
      {"int8", IdlKind::Int8},
      {"uint8", IdlKind::UInt8},
      {"int16", IdlKind::Int16},
      {"uint16", IdlKind::UInt16},
      {"int32", IdlKind::Int32},
      {"uint32", IdlKind::UInt32},
      {"int64", IdlKind::Int64},
      {"uint64", IdlKind::UInt64},
      {"float", IdlKind::Float},
      {"double", IdlKind::Double},
      {"short", IdlKind::Int16},
      {"long", IdlKind::Int32},
      {"string", IdlKind::String},
      {"unsigned short", IdlKind::UInt16},
      {"unsigned long", IdlKind::UInt32},
      {"long long", IdlKind::Int64},
      {"unsigned long long", IdlKind::UInt64},
  };
  return names;
}

}  // namespace

class IdlParser {
 public:
  IdlParser(IdlSchema& schema, std::vector<Token> tokens)
      : schema_(schema), tokens_(std::move(tokens)) {}

  void definitions(bool in_module) {
    while (pos_ < tokens_.size()) {
      skip_annotations();
      if (pos_ >= tokens_.size()) return;
      const std::string& word = peek();
      if (word == "}" && in_module) return;
      if (word == ";") {
        ++pos_;
      } else if (word == "module") {
        ++pos_;
        scope_.push_back(identifier());
        expect("{");
        definitions(true);
        expect("}");
        scope_.pop_back();
      } else if (word == "struct") {
        ++pos_;
        structure();
      } else if (word == "typedef") {
        ++pos_;
        IdlType type = type_spec();
        std::string name = identifier();
        type.array = dimensions();
        schema_.typedefs_[qualified(name)] = type;
      } else if (word == "enum") {
        ++pos_;
        std::string name = identifier();
        schema_.enums_[qualified(name)] = 0;
        expect("{");
        skip_to("}");
        expect("}");
      } else if (word == "const") {
        skip_to(";");
      } else {
        fail(fmt::format("unsupported IDL construct '{}'", word));
      }
    }
  }

 private:
  void structure() {
    std::string name = qualified(identifier());
    if (peek() == ";") return;  // forward declaration
    if (peek() == ":") fail("struct inheritance is not supported");
    expect("{");
    IdlStruct result{name, {}};
    while (peek() != "}") {
      if (pos_ >= tokens_.size()) fail("expected '}' before the end");
      skip_annotations();
      IdlType type = type_spec();
      for (;;) {
        IdlMember member{identifier(), type};
        std::vector<uint32_t> dims = dimensions();
        if (!dims.empty()) {
          if (!member.type.array.empty()) fail("arrays of array typedefs are not supported");
          member.type.array = dims;
        }
        result.members.push_back(std::move(member));
        skip_annotations();
        if (peek() != ",") break;
        ++pos_;
      }
      expect(";");
    }
    expect("}");
    schema_.structs_[name] = std::move(result);
  }

  IdlType type_spec() {
    std::string word = identifier_or_scope();
    if (word == "sequence") {
      expect("<");
      IdlType element = type_spec();
      if (peek() == ",") {
        ++pos_;
        number();
      }
      expect(">");
      IdlType type{IdlKind::Sequence, "", std::make_shared<const IdlType>(element), {}};
      return type;
    }
    if (word == "string" || word == "wstring") {
      if (word == "wstring") fail("wstring is not supported");
      if (peek() == "<") {
        ++pos_;
        number();
        expect(">");
      }
      return {IdlKind::String, "", nullptr, {}};
    }
    if (word == "unsigned" || word == "long") {
      std::string full = word;
      while (peek() == "short" || peek() == "long" || (full == "long" && peek() == "double")) {
        full += " " + tokens_[pos_++].text;
      }
      if (full == "long double") fail("long double is not supported");
      word = full;
    }
    if (auto it = primitive_names().find(word); it != primitive_names().end()) {
      return {it->second, "", nullptr, {}};
    }
    // A typedef, enum or struct, relative to the enclosing modules or fully qualified.
    std::string name = word;
    while (peek() == "::") {
      ++pos_;
      name += "::" + identifier();
    }
    if (name.starts_with("::")) name.erase(0, 2);
    for (size_t depth = scope_.size() + 1; depth-- > 0;) {
      std::string candidate;
      for (size_t k = 0; k < depth; ++k) candidate += scope_[k] + "::";
      candidate += name;
      if (auto it = schema_.typedefs_.find(candidate); it != schema_.typedefs_.end()) {
        return it->second;
      }
      if (schema_.enums_.contains(candidate)) return {IdlKind::Enum, candidate, nullptr, {}};
      if (schema_.structs_.contains(candidate)) return {IdlKind::Struct, candidate, nullptr, {}};
    }
    // Defined elsewhere (another file): qualified names are taken as they are.
    return {IdlKind::Struct,
            name.find("::") == std::string::npos ? qualified(name) : name,
            nullptr,
            {}};
  }

  std::vector<uint32_t> dimensions() {
    std::vector<uint32_t> dims;
    while (peek() == "[") {
      ++pos_;
      dims.push_back(number());
      expect("]");
    }
    return dims;
  }

  void skip_to(std::string_view token) {
    while (peek() != token) {
      if (pos_ >= tokens_.size()) fail(fmt::format("expected '{}' before the end", token));
      ++pos_;
    }
  }

  void skip_annotations() {
    while (pos_ < tokens_.size() && peek() == "@") {
      pos_ += 2;  // '@' and the annotation name
      if (pos_ < tokens_.size() && peek() == "(") {
        int depth = 0;
        do {
          if (peek() == "(") ++depth;
          if (peek() == ")") --depth;
          ++pos_;
        } while (depth > 0 && pos_ < tokens_.size());
      }
    }
  }

  std::string qualified(const std::string& name) const {
    std::string out;
    for (const std::string& module : scope_) out += module + "::";
    return out + name;
  }

  const std::string& peek() const {
    static const std::string end = "<end of text>";
    return pos_ < tokens_.size() ? tokens_[pos_].text : end;
  }

  std::string identifier() {
    const std::string& word = peek();
    if (word.empty() || !(std::isalpha(static_cast<unsigned char>(word[0])) || word[0] == '_')) {
      fail(fmt::format("expected a name, found '{}'", word));
    }
    return tokens_[pos_++].text;
  }

  std::string identifier_or_scope() {
    if (peek() == "::") {
      ++pos_;
      return "::" + identifier();
    }
    return identifier();
  }

  uint32_t number() {
    const std::string& word = peek();
    uint32_t value = 0;
    auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
    if (error != std::errc() || end != word.data() + word.size()) {
      fail(fmt::format("expected a number, found '{}'", word));
    }
    ++pos_;
    return value;
  }

  void expect(std::string_view text) {
    if (peek() != text) fail(fmt::format("expected '{}', found '{}'", text, peek()));
    ++pos_;
  }

  [[noreturn]] void fail(const std::string& message) const {
    int line = tokens_.empty() ? 0 : tokens_[std::min(pos_, tokens_.size() - 1)].line;
    throw IdlError(fmt::format("IDL line {}: {}", line, message));
  }

  IdlSchema& schema_;
  std::vector<Token> tokens_;
  size_t pos_ = 0;
  std::vector<std::string> scope_;
};

void IdlSchema::parse(std::string_view text) {
  IdlParser(*this, tokenize(text)).definitions(false);
}

const IdlStruct* IdlSchema::find(std::string_view name) const {
  std::string key(name);
  for (size_t at; (at = key.find('/')) != std::string::npos;) key.replace(at, 1, "::");
  auto it = structs_.find(key);
  return it == structs_.end() ? nullptr : &it->second;
}

}  // namespace mocap
