// The history of a Cyclone DDS reader that can be told to let go before the reader is deleted.
//
// Cyclone 0.10 applies a reliable keep-all reader's resource limit by holding the receive
// thread on a sample the full history rejects, retrying every 10 ms, until there is room.
// Deleting such a reader waits for that very thread (the reader is freed only once every
// thread has moved on), which never moves on: the process hangs on exit while a publisher
// still has samples for it. This history is Cyclone's own (every operation forwarded to it)
// until close() is called; from then on it accepts and discards what arrives, so the receive
// thread moves on and the reader can go.
#pragma once

#include <dds/dds.h>

namespace mocap {

class CycloneReaderHistory;

// A history for dds_create_reader_rhc(); the reader owns it and frees it when deleted.
CycloneReaderHistory* make_cyclone_reader_history();
// Called just before the reader is deleted, with its listener already removed.
void close(CycloneReaderHistory* history);
// After dds_create_reader_rhc() failed: frees `history` if Cyclone never took it.
void free_if_unused(CycloneReaderHistory* history);
// The pointer dds_create_reader_rhc() takes.
struct dds_rhc* as_rhc(CycloneReaderHistory* history);

}  // namespace mocap
