#include "dds/cyclonedds/cyclonedds_type_support.hpp"

#include <cstring>
#include <memory>
#include <new>
#include <string>

#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <dds/ddsi/q_radmin.h>

namespace mocap {
namespace {

struct Sertype : ddsi_sertype {
  const MessageType* type = nullptr;
};

// A sample as Cyclone holds it: the encapsulated CDR, followed by up to three zero bytes,
// because Cyclone sends payloads in multiples of four bytes and reads up to the next one.
struct Serdata : ddsi_serdata {
  Serdata(const ddsi_sertype* sertype, ddsi_serdata_kind kind) : ddsi_serdata{} {
    ddsi_serdata_init(this, sertype, kind);
  }
  // Room for `size` bytes; returns where to write them.
  uint8_t* resize(size_t size) {
    bytes.assign((size + 3) & ~size_t{3}, 0);
    this->size = size;
    return bytes.data();
  }
  std::vector<uint8_t> bytes;
  size_t size = 0;
};

const MessageType& message_type_of(const ddsi_sertype* sertype) {
  return *static_cast<const Sertype*>(sertype)->type;
}

// Cyclone calls these from C: no exception may leave them. A null serdata tells it the sample
// could not be made.

uint32_t serdata_size(const ddsi_serdata* d) {
  return static_cast<uint32_t>(static_cast<const Serdata*>(d)->size);
}

void serdata_free(ddsi_serdata* d) { delete static_cast<Serdata*>(d); }

ddsi_serdata* serdata_from_ser(const ddsi_sertype* sertype, ddsi_serdata_kind kind,
                               const nn_rdata* fragment, size_t size) {
  try {
    auto d = std::make_unique<Serdata>(sertype, kind);
    uint8_t* out = d->resize(size);
    // Fragments arrive in order and may overlap; copy what each adds.
    uint32_t offset = 0;
    for (; fragment != nullptr; fragment = fragment->nextfrag) {
      if (fragment->maxp1 <= offset) continue;
      const unsigned char* payload =
          NN_RMSG_PAYLOADOFF(fragment->rmsg, NN_RDATA_PAYLOAD_OFF(fragment));
      uint32_t end = std::min<uint32_t>(fragment->maxp1, static_cast<uint32_t>(size));
      if (end > offset) std::memcpy(out + offset, payload + (offset - fragment->min), end - offset);
      offset = fragment->maxp1;
    }
    return d.release();
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}

ddsi_serdata* serdata_from_ser_iov(const ddsi_sertype* sertype, ddsi_serdata_kind kind,
                                   ddsrt_msg_iovlen_t count, const ddsrt_iovec_t* iov,
                                   size_t size) {
  try {
    auto d = std::make_unique<Serdata>(sertype, kind);
    uint8_t* out = d->resize(size);
    size_t offset = 0;
    for (ddsrt_msg_iovlen_t i = 0; i < count && offset < size; ++i) {
      size_t n = std::min<size_t>(iov[i].iov_len, size - offset);
      std::memcpy(out + offset, iov[i].iov_base, n);
      offset += n;
    }
    return d.release();
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}

// The topics have no key: a key-only sample is empty.
ddsi_serdata* serdata_from_keyhash(const ddsi_sertype* sertype, const ddsi_keyhash*) {
  return new (std::nothrow) Serdata(sertype, SDK_KEY);
}

ddsi_serdata* serdata_from_sample(const ddsi_sertype* sertype, ddsi_serdata_kind kind,
                                  const void* sample) {
  try {
    auto d = std::make_unique<Serdata>(sertype, kind);
    if (kind == SDK_DATA) {
      const MessageType& type = message_type_of(sertype);
      size_t size = type.serialized_size(sample);
      uint8_t* out = d->resize(size);
      d->size = type.serialize(sample, {out, size});
    }
    return d.release();
  } catch (const std::exception&) {  // SerializationError, bad_alloc
    return nullptr;
  }
}

void serdata_to_ser(const ddsi_serdata* d, size_t offset, size_t size, void* buffer) {
  std::memcpy(buffer, static_cast<const Serdata*>(d)->bytes.data() + offset, size);
}

ddsi_serdata* serdata_to_ser_ref(const ddsi_serdata* d, size_t offset, size_t size,
                                 ddsrt_iovec_t* ref) {
  ref->iov_base = const_cast<uint8_t*>(static_cast<const Serdata*>(d)->bytes.data()) + offset;
  ref->iov_len = static_cast<ddsrt_iov_len_t>(size);
  return ddsi_serdata_ref(d);
}

void serdata_to_ser_unref(ddsi_serdata* d, const ddsrt_iovec_t*) { ddsi_serdata_unref(d); }

// Samples are taken as serialized bytes (dds_takecdr), never as typed samples.
bool serdata_to_sample(const ddsi_serdata*, void*, void**, void*) { return false; }

ddsi_serdata* serdata_to_untyped(const ddsi_serdata* d) {
  auto* untyped = new (std::nothrow) Serdata(d->type, SDK_KEY);
  if (untyped != nullptr) untyped->type = nullptr;
  return untyped;
}

bool serdata_untyped_to_sample(const ddsi_sertype*, const ddsi_serdata*, void*, void**, void*) {
  return true;
}

bool serdata_eqkey(const ddsi_serdata*, const ddsi_serdata*) { return true; }

size_t serdata_print(const ddsi_sertype*, const ddsi_serdata* d, char* buffer, size_t size) {
  return static_cast<size_t>(
      std::snprintf(buffer, size, "(%zu bytes)", static_cast<const Serdata*>(d)->size));
}

void serdata_get_keyhash(const ddsi_serdata*, ddsi_keyhash* hash, bool) {
  std::memset(hash, 0, sizeof(*hash));
}

ddsi_serdata* serdata_from_iox(const ddsi_sertype*, ddsi_serdata_kind, void*, void*) {
  return nullptr;  // Iceoryx shared memory is not configured
}

const ddsi_serdata_ops kSerdataOps = {serdata_eqkey,
                                      serdata_size,
                                      serdata_from_ser,
                                      serdata_from_ser_iov,
                                      serdata_from_keyhash,
                                      serdata_from_sample,
                                      serdata_to_ser,
                                      serdata_to_ser_ref,
                                      serdata_to_ser_unref,
                                      serdata_to_sample,
                                      serdata_to_untyped,
                                      serdata_untyped_to_sample,
                                      serdata_free,
                                      serdata_print,
                                      serdata_get_keyhash
#ifdef DDS_HAS_SHM
                                      ,
                                      ddsi_serdata_iox_size,
                                      serdata_from_iox
#endif
};

void sertype_free(ddsi_sertype* sertype) {
  ddsi_sertype_fini(sertype);
  delete static_cast<Sertype*>(sertype);
}

void sertype_zero_samples(const ddsi_sertype*, void*, size_t) {}
void sertype_realloc_samples(void** pointers, const ddsi_sertype*, void*, size_t, size_t count) {
  for (size_t i = 0; i < count; ++i) pointers[i] = nullptr;
}
void sertype_free_samples(const ddsi_sertype*, void**, size_t, dds_free_op_t) {}

// Two sertypes of one name are the same type when they serialize with the same MessageType.
bool sertype_equal(const ddsi_sertype* a, const ddsi_sertype* b) {
  return &message_type_of(a) == &message_type_of(b);
}

uint32_t sertype_hash(const ddsi_sertype* sertype) {
  return static_cast<uint32_t>(std::hash<const void*>{}(&message_type_of(sertype)));
}

size_t sertype_serialized_size(const ddsi_sertype* sertype, const void* sample) {
  try {
    return message_type_of(sertype).serialized_size(sample);
  } catch (const std::exception&) {
    return 0;
  }
}

bool sertype_serialize_into(const ddsi_sertype* sertype, const void* sample, void* buffer,
                            size_t size) {
  try {
    message_type_of(sertype).serialize(sample, {static_cast<uint8_t*>(buffer), size});
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

const ddsi_sertype_ops kSertypeOps = {
    ddsi_sertype_v0,
    nullptr,
    sertype_free,
    sertype_zero_samples,
    sertype_realloc_samples,
    sertype_free_samples,
    sertype_equal,
    sertype_hash,
    nullptr,  // type_id, type_map, type_info: no XTypes type discovery; matched by name
    nullptr,
    nullptr,
    nullptr,  // derive_sertype: XCDR1 only
    sertype_serialized_size,
    sertype_serialize_into,
};

}  // namespace

ddsi_sertype* make_cyclonedds_sertype(const MessageType& type) {
  auto* sertype = new Sertype();
  ddsi_sertype_init_flags(sertype, type.dds_name().c_str(), &kSertypeOps, &kSerdataOps,
                          DDSI_SERTYPE_FLAG_TOPICKIND_NO_KEY);
  sertype->allowed_data_representation = DDS_DATA_REPRESENTATION_FLAG_XCDR1;
  sertype->type = &type;
  return sertype;
}

std::span<const uint8_t> serialized_bytes(const ddsi_serdata* serdata) {
  const auto* d = static_cast<const Serdata*>(serdata);
  return {d->bytes.data(), d->size};
}

void release(ddsi_serdata* serdata) { ddsi_serdata_unref(serdata); }

}  // namespace mocap
