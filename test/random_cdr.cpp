#include "test/random_cdr.hpp"

#include <cstring>
#include <stdexcept>
#include <string>

namespace mocap::test {
namespace {

class Writer {
 public:
  Writer(const IdlSchema& schema, std::mt19937& random) : schema_(schema), random_(random) {}

  void structure(std::string_view name) {
    const IdlStruct* type = schema_.find(name);
    if (type == nullptr) throw std::runtime_error("no IDL for " + std::string(name));
    for (const IdlMember& member : type->members) value(member.type);
  }

  std::vector<uint8_t> bytes = {0x00, 0x01, 0x00, 0x00};  // CDR_LE encapsulation

 private:
  void value(const IdlType& type) {
    if (!type.array.empty()) {
      size_t count = 1;
      for (uint32_t d : type.array) count *= d;
      IdlType element = type;
      element.array.clear();
      for (size_t i = 0; i < count; ++i) value(element);
      return;
    }
    switch (type.kind) {
      case IdlKind::Bool:
        put<uint8_t>(static_cast<uint8_t>(random_() % 2));
        break;
      case IdlKind::Char:
        put<uint8_t>(static_cast<uint8_t>('a' + random_() % 26));
        break;
      case IdlKind::Octet:
      case IdlKind::UInt8:
      case IdlKind::Int8:
        put<uint8_t>(static_cast<uint8_t>(random_()));
        break;
      case IdlKind::Int16:
      case IdlKind::UInt16:
        put<uint16_t>(static_cast<uint16_t>(random_()));
        break;
      case IdlKind::Int32:
      case IdlKind::UInt32:
      case IdlKind::Enum:
        put<uint32_t>(static_cast<uint32_t>(random_()));
        break;
      case IdlKind::Int64:
      case IdlKind::UInt64:
        put<uint64_t>((uint64_t(random_()) << 32) | random_());
        break;
      case IdlKind::Float:
        put<float>(std::uniform_real_distribution<float>(-1e4f, 1e4f)(random_));
        break;
      case IdlKind::Double:
        put<double>(std::uniform_real_distribution<double>(-1e6, 1e6)(random_));
        break;
      case IdlKind::String: {
        uint32_t length = random_() % 9;
        put<uint32_t>(length + 1);
        for (uint32_t i = 0; i < length; ++i)
          bytes.push_back(static_cast<uint8_t>('A' + random_() % 58));
        bytes.push_back(0);
        break;
      }
      case IdlKind::Sequence: {
        uint32_t count = random_() % 4;
        put<uint32_t>(count);
        for (uint32_t i = 0; i < count; ++i) value(*type.element);
        break;
      }
      case IdlKind::Struct:
        structure(type.name);
        break;
    }
  }

  template <class T>
  void put(T v) {
    while ((bytes.size() - 4) % sizeof(T) != 0) bytes.push_back(0);
    uint8_t raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));  // this machine is little endian, like CDR_LE
    bytes.insert(bytes.end(), raw, raw + sizeof(T));
  }

  const IdlSchema& schema_;
  std::mt19937& random_;
};

}  // namespace

std::vector<uint8_t> random_cdr(const IdlSchema& schema, std::string_view type,
                                std::mt19937& random) {
  Writer writer(schema, random);
  writer.structure(type);
  return std::move(writer.bytes);
}

}  // namespace mocap::test
