// The files Fast DDS's shared-memory transport keeps in /dev/shm, and what a process that
// starts does about those a killed or crashed process left behind.
//
// Each participant has a segment, fastrtps_<16 hex> (8 MiB of RAM until reboot), and two ports
// it reads from, fastrtps_port<number> (with a semaphore sem.fastrtps_port<number>_mutex). The
// port numbers follow from the domain and the participant id as the UDP ports do. A live
// participant holds a lock on the file <name>_el of each; a lock file nobody holds belongs to
// a dead process.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>

namespace mocap {

struct SharedMemoryCleanup {
  int files = 0;
  uintmax_t bytes = 0;
};

// Removes the segments of dead participants, with their lock files. Files younger than
// `min_age` are left alone: a participant being created may not hold its lock yet. Ports are
// kept: see unused_participant_id().
SharedMemoryCleanup remove_orphaned_shared_memory(
    const std::filesystem::path& directory = "/dev/shm",
    std::chrono::seconds min_age = std::chrono::seconds(30));

// The lowest participant id on `domain_id` whose ports no participant, live or dead, has left
// in `directory`; if every id's have been used, the id whose dead participant opened them
// longest ago; nullopt if all are live.
//
// A process that opens the port of a dead one removes it and makes a new one under the same
// name, while a running peer that wrote to the dead process still writes to the old one:
// nothing it sends reaches the new process, which then waits forever for a reliable
// publisher's data and holds that publisher up (Fast DDS 2.9.1; the peer notices only if the
// dead process was waiting for data when it died). Fast DDS gives a new participant the
// lowest free id, so a restarted process would take exactly the ports of the one it replaces.
std::optional<int> unused_participant_id(int domain_id,
                                         const std::filesystem::path& directory = "/dev/shm");

}  // namespace mocap
