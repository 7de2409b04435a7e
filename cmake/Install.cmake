# `cmake --install build --prefix P`:
#
#   P/bin/                         mocap_launch, mocap_topic, mocap_bag, mocap_calibrate,
#                                  mocap_calibration_record; mocap_msg_to_idl (dev)
#   P/lib/                         the runtime, message and bag libraries; calibration archives
#   P/lib/mocap_graph/plugins/     every shipped plugin (mocap_launch's default search path)
#   P/include/                     component API, messages, camera models and calibration, bags
#   P/share/mocap_graph/config/    the shipped configuration (plugins' default files)
#   P/share/mocap_graph/launch_yaml/  the shipped launch files (their ../config paths hold)
#   P/share/mocap_graph/idl/       the shipped messages as IDL and .msg files, for your own
#                                  messages to use
#   P/share/mocap_graph/scripts/   scenario.sh: one host of the multi-host scenario;
#                                  healthcheck.sh: a container's HEALTHCHECK
#   P/lib/cmake/mocap_graph/       find_package(mocap_graph): imported targets mocap_graph::*,
#                                  mocap_add_plugin and mocap_generate_messages
include(CMakePackageConfigHelpers)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/config DESTINATION share/mocap_graph)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/launch_yaml DESTINATION share/mocap_graph)
# One host's share of the multi-host scenario, and the containers' health check.
install(PROGRAMS ${PROJECT_SOURCE_DIR}/scripts/scenario.sh
                 ${PROJECT_SOURCE_DIR}/scripts/healthcheck.sh DESTINATION share/mocap_graph/scripts)

set(package_dir lib/cmake/mocap_graph)
install(EXPORT mocap_graph_targets NAMESPACE mocap_graph:: DESTINATION ${package_dir}
        FILE mocap_graph_targets.cmake COMPONENT dev)
set(MOCAP_SHARE_DIR share/mocap_graph)
configure_package_config_file(cmake/mocap_graphConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/mocap_graphConfig.cmake
                              INSTALL_DESTINATION ${package_dir}
                              PATH_VARS MOCAP_SHARE_DIR)
# A project asking for 0.1 accepts any 0.1.x. Whatever the version, the loader checks the
# component ABI (ComponentFactory::kAbiVersion) and refuses a plugin built for another by name.
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/mocap_graphConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/mocap_graphConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/mocap_graphConfigVersion.cmake
              cmake/MocapAddPlugin.cmake cmake/MocapGenerateMessages.cmake cmake/generate_idl.cmake
        DESTINATION ${package_dir} COMPONENT dev)
install(DIRECTORY cmake/message_templates DESTINATION ${package_dir} COMPONENT dev)
