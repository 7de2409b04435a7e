// Cyclone DDS type support for any MessageType, so one implementation serves every generated
// type and the raw bytes of tools alike: samples travel as the MessageType's own encapsulated
// XCDR1 bytes, the same bytes Fast DDS puts on the wire.
#pragma once

#include <dds/dds.h>

#include <mocap/message_type.hpp>

namespace mocap {

// A new Cyclone sertype named type.dds_name(); dds_create_topic_sertype() takes ownership.
// dds_write() takes a pointer to a message of `type`; readers take the bytes with
// dds_takecdr() and turn them into a message with serialized_bytes().
struct ddsi_sertype* make_cyclonedds_sertype(const MessageType& type);

// The encapsulated CDR a serdata of such a sertype holds.
std::span<const uint8_t> serialized_bytes(const struct ddsi_serdata* serdata);

// Lets go of a serdata dds_takecdr() gave. (Cyclone's ddsi headers, which declare its own
// function, cannot share a file with Fast DDS's.)
void release(struct ddsi_serdata* serdata);

}  // namespace mocap
