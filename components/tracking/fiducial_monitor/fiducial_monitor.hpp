// Rate, size and latency of a message stream over a reporting interval.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace mocap::demo {

class StreamStatistics {
 public:
  struct Report {
    size_t messages;
    double mean_items;  // items per message (e.g. fiducials per array)
    double latency_median_s;
    double latency_p99_s;
    double latency_max_s;
  };

  // `latency_s`: receive time minus the message's stamp.
  void add(double latency_s, size_t items);
  // What was added since the last report, then starts a new interval; nullopt if nothing.
  std::optional<Report> report();
  size_t total_messages() const { return total_; }

 private:
  std::vector<double> latencies_;
  size_t items_ = 0;
  size_t total_ = 0;
};

}  // namespace mocap::demo
