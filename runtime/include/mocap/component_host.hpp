// One process's share of a graph: its components, executor, timers and transports.
//
// mocap_launch builds one host per launch-file group. Tests and benchmarks use it directly:
//
//   mocap::ComponentHost host({.name = "test", .dds = {.enabled = false}});
//   host.add(mocap::make_component_factory<Source>("source"), {.name = "source"});
//   host.add(mocap::make_component_factory<Sink>("sink"), {.name = "sink"});
//   int exit_code = host.run(std::chrono::seconds(2));
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <mocap/component.hpp>
#include <mocap/parameter.hpp>
#include <mocap/qos.hpp>

namespace mocap {

struct DdsOptions {
  // Off: the process talks to nobody outside itself (no participant is created).
  bool enabled = true;
  // The DDS implementation, by name: "fastdds" (eProsima Fast DDS) or "cyclonedds" (Eclipse
  // Cyclone DDS) in this build (`mocap_launch --help` lists them). All put the same wire on the
  // network, so processes on any of them talk to each other. Empty: the
  // MOCAP_DDS_IMPLEMENTATION environment variable, else the first of the list.
  std::string implementation = {};
  // 0..232; the MOCAP_DOMAIN_ID environment variable overrides it.
  int domain_id = 0;
  // DDS Security (authentication, access control, encryption): a folder made by
  // scripts/make_security.sh and the identity to take from it (NAME.cert.pem and the like).
  // Empty: no security. The MOCAP_SECURITY_DIRECTORY and MOCAP_SECURITY_IDENTITY environment
  // variables override them.
  std::string security_directory = {};
  std::string security_identity = {};
  // Samples between processes of one host through shared memory, where the implementation
  // offers it (Fast DDS does; Cyclone DDS here talks UDP only). Off: UDP only, needed between
  // containers that do not share /dev/shm, and to force the network path between network
  // namespaces.
  bool shared_memory = true;
  // Discovery through discovery servers instead of multicast, where the implementation offers
  // them (Fast DDS's Discovery Servers: the i-th "host:port" is the server started with id i,
  // `fast-discovery-server -i i -l host -p port`, as ROS_DISCOVERY_SERVER; host an IPv4 address
  // or a name). A launch file that names them for a group on an implementation without them is
  // refused. Empty: multicast discovery. The MOCAP_DISCOVERY_SERVER environment variable
  // ("host:port;..") overrides it.
  std::vector<std::string> discovery_servers = {};
};

struct HostOptions {
  std::string name = "mocap";  // process name; also the DDS participant name
  int threads = 0;             // executor threads; 0: one per CPU core
  DdsOptions dds;
  // The topics of the whole deployment (every group of the launch file), for
  // Context::known_topics(). Empty: those of the components added to this host.
  std::vector<KnownTopic> known_topics = {};
  // Rewritten every second by a callback on the executor, while the host runs: its age tells
  // a supervisor (a container's HEALTHCHECK) that the process still dispatches callbacks, which
  // a live PID alone does not. Empty: no file.
  std::string health_file = {};
};

struct ComponentConfig {
  std::string name = {};
  // Parameters not given take their declared defaults.
  std::map<std::string, ParameterValue> parameters = {};
  // Declared topic -> topic actually used.
  std::map<std::string, std::string> remaps = {};
  // Declared topic -> QoS replacing the declared one.
  std::map<std::string, Qos> qos = {};
};

// A component that could not be configured or constructed; the message names it.
class ComponentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ComponentHost {
 public:
  explicit ComponentHost(HostOptions options = {});
  ~ComponentHost();  // stops, then destroys components in reverse order of addition
  ComponentHost(const ComponentHost&) = delete;
  ComponentHost& operator=(const ComponentHost&) = delete;

  // Checks `config` against the factory's declaration and constructs the component. Throws
  // ComponentError naming the component, for bad configuration or a throwing constructor.
  Component& add(const ComponentFactory& factory, ComponentConfig config);

  // Starts callbacks and timers. Components added later start at once.
  void start();
  // start(), then blocks until SIGINT or SIGTERM, a component's request_shutdown(), or
  // `duration`; then stop(). Returns the exit code: 0, or what components requested.
  int run(std::optional<std::chrono::duration<double>> duration = std::nullopt);
  // Waits for running callbacks to return; no callback runs afterwards.
  void stop();

  // Callbacks that threw, over all components.
  uint64_t callback_errors() const;
  const HostOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Every problem with `config` for a component declared by `spec` ("parameter 'x' expects
// double, got string "a""), or an empty list. Also used by the launch file validation.
std::vector<std::string> check_component_config(const ComponentSpec& spec,
                                                const ComponentConfig& config);

}  // namespace mocap
