// ax12_sim: a chain of simulated AX-12A servos (ax12_sim.hpp) behind a USB
// adaptor, played on a pseudo-terminal, the embedded default when no servos are attached.
// The driver opens the pseudo-terminal (or the device_link to it) like a USB2Dynamixel and
// speaks Protocol 1.0 to it, so the real driver code path runs.
//
// A worker thread reads the host's bytes, feeds them to the chain on the steady clock's time
// since the component was created, writes the answers back, and moves the servos at least
// every 2 ms while the host is quiet. It publishes nothing.
#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <mocap/component.hpp>

#include "common/serial_io/device_link.hpp"
#include "common/serial_io/serial_port.hpp"
#include "follower/dynamixel/ax12_control_table.hpp"
#include "sim/ax12_sim/ax12_sim.hpp"

namespace mocap::dynamixel {
namespace {

using Steady = std::chrono::steady_clock;

// How long the worker waits for the host's bytes before it moves the servos anyway.
constexpr std::chrono::milliseconds kStepPeriod{2};
// A host that stops reading fills the pty's buffer; the answer is dropped after this long,
// as on a bus where nobody listens.
constexpr std::chrono::milliseconds kPtyWriteTimeout{100};

std::vector<uint8_t> servo_ids(const std::vector<int64_t>& values) {
  if (values.empty()) throw std::invalid_argument("parameter 'ids' is empty: no servos");
  std::vector<uint8_t> ids;
  for (int64_t id : values) ids.push_back(static_cast<uint8_t>(id));  // range-checked: 0..253
  return ids;
}

struct Settings {
  std::vector<int64_t> ids = {1, 2};
  std::vector<int> initial_positions;
  std::vector<std::string> faults;
  int baud = 1000000;
  std::string device_link;
};

const ParameterList<Settings> kParameters =
    ParameterList<Settings>()
        .add("ids", "the servos' IDs, distinct", &Settings::ids)
        .range(0, 253)
        .add("initial_positions",
             "present position of each servo (same order as ids), position units; empty = "
             "512 (centre) for all",
             &Settings::initial_positions)
        .range(0, 1023)
        .add("faults",
             "injected faults as ID:FAULT, FAULT one of silent (no answer), corrupt (bad "
             "checksums), overheat, overload, none; e.g. [\"2:overheat\"]",
             &Settings::faults)
        .add("baud",
             "the bus's bit rate, informational: a pseudo-terminal passes bytes at any rate",
             &Settings::baud)
        .min(1)
        .add("device_link",
             "symbolic link to create to the pseudo-terminal (replacing an older link), "
             "for the driver's `device`; empty = none (the log names the pty)",
             &Settings::device_link)
        .path();

class Ax12Sim final : public Component {
  // Before the other members, which may start from it.
  const Settings settings_ = read_settings(kParameters);

 public:
  static void declare(ComponentSpec& spec) {
    spec.description(
        "Simulated AX-12A servo chain on a pseudo-terminal: answers Dynamixel Protocol 1.0 "
        "instructions (PING, READ, WRITE, REG_WRITE/ACTION, SYNC_WRITE, RESET) like the real "
        "servos and moves them toward their goal positions at their moving speeds, for the "
        "Dynamixel driver when no servos are attached. Publishes nothing.");
    kParameters.declare(spec);
  }

  explicit Ax12Sim(Context& context) : Component(context), chain_(servo_ids(settings_.ids)) {
    const std::vector<uint8_t> ids = chain_.ids();
    const std::vector<int> positions = settings_.initial_positions;
    if (!positions.empty() && positions.size() != ids.size()) {
      throw std::invalid_argument(
          fmt::format("parameter 'initial_positions' has {} values for {} servos", positions.size(),
                      ids.size()));
    }
    for (size_t i = 0; i < positions.size(); ++i) {
      chain_.set_position(ids[i], static_cast<uint16_t>(positions[i]));
    }
    std::string faults;
    for (const std::string& text : settings_.faults) {
      const auto [id, fault] = parse_ax12_fault_spec(text);
      if (!chain_.has_servo(id)) {
        throw std::invalid_argument(
            fmt::format("fault '{}': no servo with ID {} in 'ids'", text, id));
      }
      chain_.set_fault(id, fault);
      faults += fmt::format(", servo {} {}", id, to_string(fault));
    }
    pty_.emplace(serial::PseudoTerminalOptions{.write_timeout = kPtyWriteTimeout});
    const std::string link = settings_.device_link;
    if (!link.empty()) {
      device_link_.emplace(link, pty_->slave_path());
    }
    log().info("simulated AX-12A chain on {}{}: servos {} at {} bit/s{}", pty_->slave_path(),
               link.empty() ? "" : " (link " + link + ")", fmt::join(ids, ", "), settings_.baud,
               faults);
    start_ = Steady::now();
    create_worker("servo chain", [this](std::stop_token stop) { play(stop); });
  }

  ~Ax12Sim() override {
    device_link_.reset();
    pty_->close_master();
    const SimulatedAx12ChainStats& s = chain_.stats();
    std::string positions;
    for (uint8_t id : chain_.ids()) {
      positions += fmt::format("{}servo {} at {}", positions.empty() ? "" : ", ", id,
                               chain_.register_u16(id, ax12::kPresentPosition));
    }
    log().info(
        "{} instructions ({} with bad checksums, {} for absent IDs), {} answers, {} failed "
        "writes; {}",
        s.instructions, s.checksum_errors, s.unaddressed, s.replies, failed_writes_, positions);
  }

 private:
  double time_s() const { return std::chrono::duration<double>(Steady::now() - start_).count(); }

  void play(std::stop_token stop) {
    char buffer[512];
    while (!stop.stop_requested()) {
      size_t count = 0;
      try {
        count = pty_->read(buffer, sizeof buffer, kStepPeriod);
      } catch (const serial::SerialError& e) {
        log().error("{}; the simulated servos stop", e.what());
        return;
      }
      if (count == 0) {
        chain_.advance(time_s());
        continue;
      }
      const std::string answers = chain_.feed(std::string_view(buffer, count), time_s());
      if (answers.empty()) continue;
      try {
        pty_->write_all(answers);
      } catch (const serial::SerialError& e) {
        if (failed_writes_++ == 0) log().warn("cannot answer the host: {}", e.what());
      }
    }
  }

  // The chain and the counter belong to the worker until it ends (the host joins it before
  // destroying the component).
  SimulatedAx12Chain chain_;
  uint64_t failed_writes_ = 0;
  std::optional<serial::PseudoTerminal> pty_;
  std::optional<serial::DeviceLink> device_link_;
  Steady::time_point start_;
};

}  // namespace
}  // namespace mocap::dynamixel

MOCAP_REGISTER_COMPONENT(mocap::dynamixel::Ax12Sim, "ax12_sim")
