// Quality of service of a topic endpoint, with the three named profiles of the launch files.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

namespace mocap {

enum class Reliability { BestEffort, Reliable };
enum class Durability { Volatile, TransientLocal };
enum class History { KeepLast, KeepAll };

// The same rules apply in-process and over DDS, so a component behaves the same whether its
// peers are local or remote.
struct Qos {
  Reliability reliability = Reliability::Reliable;
  Durability durability = Durability::Volatile;
  History history = History::KeepAll;
  // KeepLast: samples kept per endpoint, the oldest dropped first. KeepAll: samples a
  // subscriber may fall behind before its publishers wait for it.
  int depth = 1000;
  // A reliable keep-all publisher whose subscriber is `depth` samples behind waits for it as
  // long as that subscriber exists: nothing is lost, and the slowest subscriber sets the pace.
  // Set, the publisher waits at most this long per sample, then drops the sample for that
  // subscriber (counted and logged), for streams that must never hold their producer up.
  std::optional<std::chrono::milliseconds> max_blocking = std::nullopt;

  // Streams where the newest sample matters most: best effort, volatile, keep last 5.
  static Qos sensor_data();
  // Nothing lost while subscribers keep within `depth` samples: reliable, keep all.
  static Qos reliable();
  // The last sample is kept for late subscribers: reliable, transient local, keep last 1.
  static Qos latched();

  // "sensor_data", "reliable" or "latched"; nullopt for anything else.
  static std::optional<Qos> from_profile(std::string_view profile);
  static constexpr std::string_view profile_names = "sensor_data, reliable, latched";

  // "reliable, transient_local, keep_last 1" (or the profile name when it is one), with
  // ", max_blocking 100 ms" when set.
  std::string to_string() const;
  bool operator==(const Qos&) const = default;
};

// True when a publisher with `offered` may have to wait for a subscriber with `requested`:
// both reliable and keep-all, as in DDS, where a keep-last writer overwrites its oldest
// sample and a keep-last reader acknowledges what it overwrites.
bool publisher_may_wait(const Qos& offered, const Qos& requested);

// DDS request/offer rules: a reliable subscriber needs a reliable publisher, a transient
// local subscriber needs a transient local publisher. Returns why they do not match, or
// nullopt when they do.
std::optional<std::string> qos_mismatch(const Qos& offered, const Qos& requested);

}  // namespace mocap
