// A component's parameters, each written once: its name, description and range, and the member
// of the component's settings struct it sets, whose initializer is the default.
//
//   struct Settings {
//     FiducialDetectorOptions detector;  // the algorithm's options, defaults in its header
//     double report_period_s = 5;
//   };
//   const ParameterList<Settings> kParameters = ParameterList<Settings>()
//       .add("threshold_ratio", "fraction of the brightest pixel", &Settings::detector,
//            &FiducialDetectorOptions::threshold_ratio).range(0, 1)
//       .add("report_period_s", "seconds between summary lines", &Settings::report_period_s)
//           .range(0.1, 86400);
//
//   class FiducialTracker final : public Component {
//     const Settings settings_ = read_settings(kParameters);  // before the members using it
//    public:
//     static void declare(ComponentSpec& spec) { kParameters.declare(spec); ... }
//     ...
//
// The launcher validates a launch file's values against the declaration and `mocap_launch
// --describe` prints it, so the default a user reads is the one the code starts from.
#pragma once

#include <functional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <mocap/component_spec.hpp>
#include <mocap/parameter.hpp>

namespace mocap {

template <class Settings>
class ParameterList {
 public:
  // Declares parameter `name`, bound to the member `path` leads to from Settings: one member
  // pointer, or several for a member of a member (&Settings::detector, &Options::ratio). The
  // member's type is the parameter's: bool, an integer, a floating-point number, std::string,
  // or a std::vector of int, int64_t, double or std::string. An unsigned member gets min(0).
  template <class... Path>
  ParameterList& add(std::string name, std::string description, Path... path) {
    static_assert(sizeof...(Path) > 0, "a parameter is bound to a member of Settings");
    using Member = std::remove_reference_t<decltype((std::declval<Settings&>().*....*path))>;
    ParameterSpec spec;
    spec.name = std::move(name);
    spec.description = std::move(description);
    if constexpr (std::is_unsigned_v<Member> && !std::is_same_v<Member, bool>) spec.min = 0;
    const std::string key = spec.name;
    entries_.push_back({std::move(spec),
                        [path...](const Settings& settings) {
                          return detail::to_parameter_value((settings.*....*path));
                        },
                        [key, path...](const Parameters& values, Settings& settings) {
                          (settings.*....*path) = values.get<Member>(key);
                        }});
    return *this;
  }

  // Declares every parameter of `list`, bound to the same members of `member`: for settings
  // several components share (the files a tracking stage reads, a serial port's).
  template <class Part>
  ParameterList& include(Part Settings::*member, const ParameterList<Part>& list) {
    for (const auto& entry : list.entries_) {
      entries_.push_back(
          {entry.spec,
           [member, get = entry.get](const Settings& settings) { return get(settings.*member); },
           [member, assign = entry.assign](const Parameters& values, Settings& settings) {
             assign(values, settings.*member);
           }});
    }
    return *this;
  }

  // Bounds of the parameter added last: inclusive, for numbers and each element of number lists.
  ParameterList& range(double min, double max) { return this->min(min).max(max); }
  ParameterList& min(double min) {
    entries_.back().spec.min = min;
    return *this;
  }
  ParameterList& max(double max) {
    entries_.back().spec.max = max;
    return *this;
  }
  // The parameter added last (a string or a list of strings) is a file or directory path: a
  // relative value in a launch file is taken relative to the file's folder.
  ParameterList& path() {
    entries_.back().spec.is_path = true;
    return *this;
  }

  // Adds every parameter to `spec`, in the order added, each with its member's initial value
  // in Settings{} as the default.
  void declare(ComponentSpec& spec) const {
    const Settings defaults{};
    for (const Entry& entry : entries_) {
      ParameterSpec declared = entry.spec;
      declared.default_value = entry.get(defaults);
      spec.parameter(std::move(declared));
    }
  }

  // Settings with each parameter's validated value (the launch file's, or the default).
  Settings read(const Parameters& values) const {
    Settings settings{};
    for (const Entry& entry : entries_) entry.assign(values, settings);
    return settings;
  }

 private:
  template <class Other>
  friend class ParameterList;
  struct Entry {
    ParameterSpec spec;  // without its default
    std::function<ParameterValue(const Settings&)> get;
    std::function<void(const Parameters&, Settings&)> assign;
  };

  std::vector<Entry> entries_;
};

}  // namespace mocap
