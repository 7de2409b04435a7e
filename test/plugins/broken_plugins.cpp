// Libraries that are not valid plugins, one flaw each, for the plugin loader's tests. Each
// is compiled with one of the BROKEN_* macros.
#include <mocap/component.hpp>

namespace {

#if defined(BROKEN_DECLARATION)
struct Settings {
  int first = 1;
  int second = 2;
};
#endif

class Nothing final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
#if defined(BROKEN_DECLARATION)
    mocap::ParameterList<Settings>()
        .add("twice", "declared", &Settings::first)
        .add("twice", "declared again", &Settings::second)
        .declare(spec);
#else
    (void)spec;
#endif
  }
  explicit Nothing(mocap::Context& context) : Component(context) {}
};

}  // namespace

#if defined(BROKEN_NO_SYMBOL)
extern "C" int not_a_plugin() { return 0; }
#elif defined(BROKEN_ABI)
extern "C" __attribute__((visibility("default"))) const mocap::ComponentFactory*
mocap_component_factory() {
  static const mocap::ComponentFactory factory{0, "wrong_abi", &Nothing::declare, nullptr};
  return &factory;
}
#elif defined(BROKEN_UNRESOLVED)
extern "C" void function_that_exists_nowhere();
MOCAP_REGISTER_COMPONENT(Nothing, "unresolved")
extern "C" __attribute__((visibility("default"))) void call_it() { function_that_exists_nowhere(); }
#elif defined(BROKEN_NAME)
MOCAP_REGISTER_COMPONENT(Nothing, "another_name")
#elif defined(BROKEN_DECLARATION)
MOCAP_REGISTER_COMPONENT(Nothing, "bad_declaration")
#endif
