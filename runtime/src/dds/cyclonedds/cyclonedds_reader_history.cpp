#include "dds/cyclonedds/cyclonedds_reader_history.hpp"

#include <atomic>

#include <dds/ddsc/dds_rhc.h>

// Cyclone's default reader history (dds__rhc_default.h, not installed; exported by libddsc).
extern "C" struct dds_rhc* dds_rhc_default_new(struct dds_reader* reader,
                                               const struct ddsi_sertype* type);

namespace mocap {

class CycloneReaderHistory {
 public:
  dds_rhc base;  // first: Cyclone sees this object as a dds_rhc
  dds_rhc* inner = nullptr;
  std::atomic<bool> closed{false};
};

namespace {

CycloneReaderHistory* self(dds_rhc* rhc) { return reinterpret_cast<CycloneReaderHistory*>(rhc); }
CycloneReaderHistory* self(ddsi_rhc* rhc) { return reinterpret_cast<CycloneReaderHistory*>(rhc); }
ddsi_rhc* inner_ddsi(ddsi_rhc* rhc) { return &self(rhc)->inner->common.rhc; }

bool store(ddsi_rhc* __restrict rhc, const ddsi_writer_info* __restrict writer,
           ddsi_serdata* __restrict sample, ddsi_tkmap_instance* __restrict instance) {
  if (self(rhc)->closed.load()) return true;  // accepted, and dropped with the reader
  return ddsi_rhc_store(inner_ddsi(rhc), writer, sample, instance);
}

void unregister_writer(ddsi_rhc* __restrict rhc, const ddsi_writer_info* __restrict writer) {
  ddsi_rhc_unregister_wr(inner_ddsi(rhc), writer);
}

void relinquish_ownership(ddsi_rhc* __restrict rhc, const uint64_t writer) {
  ddsi_rhc_relinquish_ownership(inner_ddsi(rhc), writer);
}

void set_qos(ddsi_rhc* rhc, const dds_qos* qos) { ddsi_rhc_set_qos(inner_ddsi(rhc), qos); }

void free_history(ddsi_rhc* rhc) {
  if (self(rhc)->inner != nullptr) dds_rhc_free(self(rhc)->inner);
  delete self(rhc);
}

int32_t read(dds_rhc* rhc, bool lock, void** values, dds_sample_info_t* infos, uint32_t most,
             uint32_t mask, dds_instance_handle_t handle, dds_readcond* condition) {
  return dds_rhc_read(self(rhc)->inner, lock, values, infos, most, mask, handle, condition);
}

int32_t take(dds_rhc* rhc, bool lock, void** values, dds_sample_info_t* infos, uint32_t most,
             uint32_t mask, dds_instance_handle_t handle, dds_readcond* condition) {
  return dds_rhc_take(self(rhc)->inner, lock, values, infos, most, mask, handle, condition);
}

int32_t readcdr(dds_rhc* rhc, bool lock, ddsi_serdata** values, dds_sample_info_t* infos,
                uint32_t most, uint32_t sample_states, uint32_t view_states,
                uint32_t instance_states, dds_instance_handle_t handle) {
  return dds_rhc_readcdr(self(rhc)->inner, lock, values, infos, most, sample_states, view_states,
                         instance_states, handle);
}

int32_t takecdr(dds_rhc* rhc, bool lock, ddsi_serdata** values, dds_sample_info_t* infos,
                uint32_t most, uint32_t sample_states, uint32_t view_states,
                uint32_t instance_states, dds_instance_handle_t handle) {
  return dds_rhc_takecdr(self(rhc)->inner, lock, values, infos, most, sample_states, view_states,
                         instance_states, handle);
}

bool add_readcondition(dds_rhc* rhc, dds_readcond* condition) {
  return dds_rhc_add_readcondition(self(rhc)->inner, condition);
}

void remove_readcondition(dds_rhc* rhc, dds_readcond* condition) {
  dds_rhc_remove_readcondition(self(rhc)->inner, condition);
}

uint32_t lock_samples(dds_rhc* rhc) { return dds_rhc_lock_samples(self(rhc)->inner); }

// The reader exists from here on: Cyclone's history is made for it now.
dds_return_t associate(dds_rhc* rhc, dds_reader* reader, const ddsi_sertype* type,
                       ddsi_tkmap* instances) {
  self(rhc)->inner = dds_rhc_default_new(reader, type);
  if (self(rhc)->inner == nullptr) return DDS_RETCODE_OUT_OF_RESOURCES;
  return dds_rhc_associate(self(rhc)->inner, reader, type, instances);
}

const dds_rhc_ops kOps = {
    {store, unregister_writer, relinquish_ownership, set_qos, free_history},
    read,
    take,
    readcdr,
    takecdr,
    add_readcondition,
    remove_readcondition,
    lock_samples,
    associate,
};

}  // namespace

CycloneReaderHistory* make_cyclone_reader_history() {
  auto* history = new CycloneReaderHistory();
  history->base.common.ops = &kOps;
  return history;
}

void close(CycloneReaderHistory* history) { history->closed.store(true); }

void free_if_unused(CycloneReaderHistory* history) {
  if (history->inner == nullptr) delete history;
}

dds_rhc* as_rhc(CycloneReaderHistory* history) { return &history->base; }

}  // namespace mocap
