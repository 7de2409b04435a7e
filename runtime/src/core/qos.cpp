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

namespace {

// Equal but for max_blocking.
bool same_policies(const Qos& a, const Qos& b) {
  return a.reliability == b.reliability && a.durability == b.durability && a.history == b.history &&
         a.depth == b.depth;
}

}  // namespace

std::string Qos::to_string() const {
  std::string text;
  if (same_policies(*this, sensor_data())) {
    text = "sensor_data";
  } else if (same_policies(*this, reliable())) {
    text = "reliable";
  } else if (same_policies(*this, latched())) {
    text = "latched";
  } else {
    text = fmt::format("{}, {}, {} {}",
                       reliability == Reliability::Reliable ? "reliable" : "best_effort",
                       durability == Durability::Volatile ? "volatile" : "transient_local",
                       history == History::KeepLast ? "keep_last" : "keep_all", depth);
  }
  if (max_blocking) text += fmt::format(", max_blocking {} ms", max_blocking->count());
  return text;
}

bool publisher_may_wait(const Qos& offered, const Qos& requested) {
  auto waits = [](const Qos& qos) {
    return qos.reliability == Reliability::Reliable && qos.history == History::KeepAll;
  };
  return waits(offered) && waits(requested);
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
