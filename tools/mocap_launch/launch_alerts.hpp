// The launcher's own voice on the graph: the supervisor's restarts and give-ups as
// mocap_msgs/Alert on /alerts, where the viewer and any DDS subscriber see them, from a DDS
// participant named "launch" in the supervising process (mocap_launch FILE, several groups).
#pragma once

#include <memory>
#include <string>

#include <mocap/component_host.hpp>

#include "launch/group_supervisor.hpp"

namespace mocap {

class LaunchAlerts {
 public:
  // Joins the DDS domain with `dds` (the launch file's settings, which its groups share).
  explicit LaunchAlerts(const DdsOptions& dds);
  ~LaunchAlerts();
  // Thread-safe; published within 20 ms on the participant's own thread.
  void publish(const SupervisorEvent& event);

 private:
  class Publisher;
  std::unique_ptr<ComponentHost> host_;
  Publisher* publisher_ = nullptr;  // owned by host_
};

}  // namespace mocap
