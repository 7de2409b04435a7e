# mocap_add_plugin(<name> SOURCES <files>... [LIBRARIES <targets>...] [OUTPUT_DIRECTORY <dir>]
#                  [COMPONENT <install component>] [NO_INSTALL])
#
# Builds the component plugin <name> as libmocap_plugin_<name>.so, the name launch
# files use (`plugin: <name>`), linked to the runtime and the messages. Only the registration
# symbol is exported, so plugins cannot clash with each other.
#
# The library goes to OUTPUT_DIRECTORY, else MOCAP_PLUGIN_OUTPUT_DIRECTORY (in this
# repository: build/lib/mocap_graph/plugins; in a project of your own: <build>/plugins, which
# you put on MOCAP_PLUGIN_PATH). `cmake --install` puts it in lib/mocap_graph/plugins, where
# the installed mocap_launch looks by default (not with NO_INSTALL: plugins for tests), as part
# of COMPONENT if given (`cmake --install --component`, and which package ships it).
include_guard(GLOBAL)

if(NOT DEFINED MOCAP_PLUGIN_OUTPUT_DIRECTORY)
  set(MOCAP_PLUGIN_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/plugins)
endif()
set(MOCAP_PLUGIN_INSTALL_DIRECTORY lib/mocap_graph/plugins)
# Installed: lib/mocap_graph/plugins/ -> lib/ (the runtime, the messages) and the message
# libraries of your own beside the plugins.
set(MOCAP_PLUGIN_INSTALL_RPATH "$ORIGIN/../..;$ORIGIN")

function(mocap_add_plugin name)
  cmake_parse_arguments(ARG "NO_INSTALL" "OUTPUT_DIRECTORY;COMPONENT" "SOURCES;LIBRARIES" ${ARGN})
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "mocap_add_plugin(${name}): no SOURCES")
  endif()
  set(target mocap_plugin_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE mocap_graph::runtime mocap_graph::messages
                                          ${ARG_LIBRARIES})
  if(NOT ARG_OUTPUT_DIRECTORY)
    set(ARG_OUTPUT_DIRECTORY ${MOCAP_PLUGIN_OUTPUT_DIRECTORY})
  endif()
  set_target_properties(${target} PROPERTIES
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY}
    INSTALL_RPATH "${MOCAP_PLUGIN_INSTALL_RPATH}")
  if(NOT ARG_NO_INSTALL)
    if(NOT ARG_COMPONENT)
      set(ARG_COMPONENT ${CMAKE_INSTALL_DEFAULT_COMPONENT_NAME})
    endif()
    if(NOT ARG_COMPONENT)
      set(ARG_COMPONENT Unspecified)  # CMake's own default
    endif()
    install(TARGETS ${target} LIBRARY DESTINATION ${MOCAP_PLUGIN_INSTALL_DIRECTORY}
            COMPONENT ${ARG_COMPONENT})
    set_property(GLOBAL APPEND PROPERTY MOCAP_PLUGINS ${target})
    set_property(GLOBAL APPEND PROPERTY MOCAP_PLUGINS_${ARG_COMPONENT} ${target})
  endif()
endfunction()
