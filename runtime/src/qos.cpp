#include <mocap/qos.hpp>

#include <fmt/format.h>

namespace mocap {

Qos Qos::sensor_data() {
  return {Reliability::BestEffort, Durability::Volatile, History::KeepLast, 5};
}

Qos Qos::reliable() {
  return {Reliability::Reliable, Durability::Volatile, History::KeepAll, 1000};
}

Qos Qos::latched() {
  return {Reliability::Reliable, Durability::TransientLocal, History::KeepLast, 1};
}

std::optional<Qos> Qos::from_profile(std::string_view profile) {
  if (profile == "sensor_data") return sensor_data();
  if (profile == "reliable") return reliable();
  if (profile == "latched") return latched();
  return std::nullopt;
}

std::string Qos::to_string() const {
  if (*this == sensor_data()) return "sensor_data";
  if (*this == reliable()) return "reliable";
  if (*this == latched()) return "latched";
  return fmt::format("{}, {}, {} {}",
                     reliability == Reliability::Reliable ? "reliable" : "best_effort",
                     durability == Durability::Volatile ? "volatile" : "transient_local",
                     history == History::KeepLast ? "keep_last" : "keep_all", depth);
}

std::optional<std::string> qos_mismatch(const Qos& offered, const Qos& requested) {
  if (requested.reliability == Reliability::Reliable &&
      offered.reliability == Reliability::BestEffort) {
    return "the subscriber requests reliable delivery but the publisher offers best_effort";
  }
  if (requested.durability == Durability::TransientLocal &&
      offered.durability == Durability::Volatile) {
    return "the subscriber requests transient_local durability but the publisher is volatile";
  }
  return std::nullopt;
}

}  // namespace mocap
