// Removes the shared-memory files that Fast DDS participants leave behind when their process
// is killed or crashes (each holds the participant's 8 MiB segment in RAM until reboot).
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>

namespace mocap {

struct SharedMemoryCleanup {
  int files = 0;
  uintmax_t bytes = 0;
};

// A live participant holds a lock on each of its "fastrtps_*_el" lock files; a lock file
// nobody holds belongs to a dead process, and goes with the files it guards. Files younger
// than `min_age` are left alone: a participant being created may not hold its lock yet.
SharedMemoryCleanup remove_orphaned_shared_memory(
    const std::filesystem::path& directory = "/dev/shm",
    std::chrono::seconds min_age = std::chrono::seconds(30));

}  // namespace mocap
