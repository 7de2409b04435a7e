# mocap_generate_messages(<pkg> <msg/Type.msg | msg/Type.idl>... [DEPENDENCIES <pkgs>...])
# mocap_generate_messages(<target> IDL_FILES <pkg/msg/Type.idl>... [IDL_ROOT <dir>]
#                         [INCLUDE_DIRS <dirs>...])
#
# Makes the shared library of message types of a package, as rosidl_generate_interfaces does
# for ROS 2. The first form is ROS 2's own layout: the target names the package, the files are
# relative to the current source directory, and .msg files are converted to IDL the way
# rosidl_adapter converts them (mocap_msg_to_idl: constants, default values, bounded strings
# and arrays). DEPENDENCIES are other packages made by mocap_generate_messages whose types
# these use (the shipped ones, std_msgs, geometry_msgs, ..., are always there). The second form
# takes IDL files laid out as <pkg>/msg/<Type>.idl under IDL_ROOT (default: the current source
# directory), several packages at once.
#
# Either way each type becomes module <pkg> { module msg { struct <Type> ... } }. For each
# type fastddsgen writes the C++ class (XCDR1 serialization), and the function adds, in ROS 2's
# layout, <pkg>/msg/<type>.hpp, the header components include, and the runtime's type support:
# components publish and subscribe the type, and mocap_topic echo, mocap_bag and any DDS peer
# see it as pkg/msg/Type, DDS type pkg::msg::dds_::Type_. The Cyclone DDS backend carries the
# same XCDR1 bytes through the runtime's own type support, so no second generator runs.
#
# Messages may use the shipped ones (geometry_msgs/Pose in a .msg file,
# #include "geometry_msgs/msg/Pose.idl" in IDL): the shipped IDL directory is on the include
# path, and the library links mocap_graph::messages.
#
# Outside this repository the library is named libmocap_messages_<target>.so and goes beside
# your plugins (MOCAP_PLUGIN_OUTPUT_DIRECTORY; installed: lib/mocap_graph/plugins), where
# mocap_topic and mocap_bag load every libmocap_messages_*.so so that they know your types.
# Sets in the caller's scope, one entry per file: <target>_CLASSES (pkg::msg::Type),
# <target>_HEADERS (pkg/msg/type.hpp) and <target>_DDS_SOURCES (fastddsgen's Fast DDS type
# supports, for programs that use Fast DDS directly; fastddsgen's code, so compile them with -w).
include_guard(GLOBAL)
include(${CMAKE_CURRENT_LIST_DIR}/MocapAddPlugin.cmake)

set(_MOCAP_MESSAGES_CMAKE_DIR ${CMAKE_CURRENT_LIST_DIR})
if(NOT FASTDDSGEN)
  find_program(FASTDDSGEN fastddsgen REQUIRED)
endif()

# The files of a package in ROS 2's layout, as <root>/<pkg>/msg/<Type>.idl in the build tree:
# .idl files copied, .msg files converted. Sets _mocap_staged_root, _mocap_staged_files
# (<pkg>/msg/<Type>.idl), _mocap_dependency_roots and _mocap_dependency_targets.
function(_mocap_stage_package package files dependencies)
  set(context "mocap_generate_messages(${package})")
  if(NOT package MATCHES "^[a-z][a-z0-9_]*$" OR package MATCHES "__|_$")
    message(FATAL_ERROR "${context}: the target names the package, so it must be a ROS 2 package "
                        "name: lower case letters, digits and single underscores")
  endif()
  set(root ${CMAKE_CURRENT_BINARY_DIR}/${package}_idl)
  set(dependency_roots)
  set(dependency_targets)
  foreach(dependency IN LISTS dependencies)
    if(TARGET ${dependency})
      get_target_property(dependency_root ${dependency} MOCAP_IDL_ROOT)
      if(NOT dependency_root)
        message(FATAL_ERROR "${context}: DEPENDENCIES ${dependency} is a target but not a message "
                            "package made by mocap_generate_messages")
      endif()
      list(APPEND dependency_roots ${dependency_root})
      list(APPEND dependency_targets ${dependency})
    elseif(NOT (DEFINED MOCAP_GRAPH_IDL_DIR AND IS_DIRECTORY ${MOCAP_GRAPH_IDL_DIR}/${dependency}))
      message(FATAL_ERROR "${context}: DEPENDENCIES ${dependency} is neither a shipped message "
                          "package nor made by mocap_generate_messages before this call")
    endif()
  endforeach()

  set(known)
  set(types)
  foreach(file IN LISTS files)
    if(file MATCHES "\\.(srv|action)$")
      message(FATAL_ERROR "${context}: ${file}: services and actions are not supported, only "
                          "messages (components talk over topics)")
    endif()
    if(NOT file MATCHES "^(.*/)?msg/([A-Za-z0-9_]+)\\.(msg|idl)$")
      message(FATAL_ERROR "${context}: ${file} is not msg/<Type>.msg or msg/<Type>.idl relative "
                          "to ${CMAKE_CURRENT_SOURCE_DIR}")
    endif()
    if(CMAKE_MATCH_2 IN_LIST types)
      message(FATAL_ERROR "${context}: two files define ${CMAKE_MATCH_2}")
    endif()
    list(APPEND types ${CMAKE_MATCH_2})
    list(APPEND known --known ${CMAKE_MATCH_2})
  endforeach()
  set(include_flags)
  foreach(dir IN LISTS dependency_roots MOCAP_GRAPH_IDL_DIR)
    list(APPEND include_flags -I ${dir})
  endforeach()

  set(staged_files)
  foreach(file IN LISTS files)
    get_filename_component(source ${file} ABSOLUTE)
    if(NOT EXISTS ${source})
      message(FATAL_ERROR "${context}: ${source} does not exist")
    endif()
    string(REGEX MATCH "msg/([A-Za-z0-9_]+)\\.(msg|idl)$" _ ${file})
    set(staged ${root}/${package}/msg/${CMAKE_MATCH_1}.idl)
    if(CMAKE_MATCH_2 STREQUAL "msg")
      add_custom_command(
        OUTPUT ${staged}
        COMMAND $<TARGET_FILE:mocap_graph::msg_to_idl> --package ${package} ${known}
                ${include_flags} ${source} ${staged}
        # The dependencies' files are staged when their targets build.
        DEPENDS ${source} $<TARGET_FILE:mocap_graph::msg_to_idl> ${dependency_targets}
        COMMENT "mocap_msg_to_idl ${file}"
        VERBATIM)
    else()
      add_custom_command(OUTPUT ${staged} COMMAND ${CMAKE_COMMAND} -E copy ${source} ${staged}
                         DEPENDS ${source} VERBATIM)
    endif()
    list(APPEND staged_files ${package}/msg/${CMAKE_MATCH_1}.idl)
  endforeach()
  set(_mocap_staged_root ${root} PARENT_SCOPE)
  set(_mocap_staged_files ${staged_files} PARENT_SCOPE)
  set(_mocap_dependency_roots ${dependency_roots} PARENT_SCOPE)
  set(_mocap_dependency_targets ${dependency_targets} PARENT_SCOPE)
endfunction()

function(mocap_generate_messages target)
  cmake_parse_arguments(ARG "" "IDL_ROOT" "IDL_FILES;INCLUDE_DIRS;DEPENDENCIES" ${ARGN})
  set(dependency_targets)
  if(ARG_IDL_FILES)
    if(ARG_UNPARSED_ARGUMENTS OR ARG_DEPENDENCIES)
      message(FATAL_ERROR "mocap_generate_messages(${target}): with IDL_FILES every file is an "
                          "IDL_FILES entry and there are no DEPENDENCIES (unexpected: "
                          "${ARG_UNPARSED_ARGUMENTS} ${ARG_DEPENDENCIES})")
    endif()
    if(NOT ARG_IDL_ROOT)
      set(ARG_IDL_ROOT ${CMAKE_CURRENT_SOURCE_DIR})
    endif()
    get_filename_component(idl_root ${ARG_IDL_ROOT} ABSOLUTE)
    foreach(idl IN LISTS ARG_IDL_FILES)
      if(NOT EXISTS ${idl_root}/${idl})
        message(FATAL_ERROR "mocap_generate_messages(${target}): ${idl_root}/${idl} does not exist")
      endif()
    endforeach()
  else()
    if(NOT ARG_UNPARSED_ARGUMENTS)
      message(FATAL_ERROR "mocap_generate_messages(${target}): no message files (msg/Type.msg, "
                          "msg/Type.idl)")
    endif()
    _mocap_stage_package(${target} "${ARG_UNPARSED_ARGUMENTS}" "${ARG_DEPENDENCIES}")
    set(idl_root ${_mocap_staged_root})
    set(ARG_IDL_FILES ${_mocap_staged_files})
    list(APPEND ARG_INCLUDE_DIRS ${_mocap_dependency_roots})
    set(dependency_targets ${_mocap_dependency_targets})
  endif()
  set(include_dirs ${idl_root} ${ARG_INCLUDE_DIRS})
  if(DEFINED MOCAP_GRAPH_IDL_DIR)
    list(APPEND include_dirs ${MOCAP_GRAPH_IDL_DIR})
  endif()
  # fastddsgen 2.3 never ends when a directory is given twice.
  list(REMOVE_DUPLICATES include_dirs)
  # A list cannot cross into a custom command's arguments intact; generate_idl.cmake splits.
  string(REPLACE ";" "|" include_dirs "${include_dirs}")
  set(generated ${CMAKE_CURRENT_BINARY_DIR}/${target}_generated)
  set(templates ${_MOCAP_MESSAGES_CMAKE_DIR}/message_templates)

  set(idl_paths)
  foreach(idl IN LISTS ARG_IDL_FILES)
    list(APPEND idl_paths ${idl_root}/${idl})
  endforeach()

  set(type_sources)
  set(support_sources)
  set(dds_sources)
  set(classes)
  set(headers)
  foreach(idl IN LISTS ARG_IDL_FILES)
    if(NOT idl MATCHES "^([A-Za-z0-9_]+)/msg/([A-Za-z0-9_]+)\\.idl$")
      message(FATAL_ERROR "mocap_generate_messages(${target}): ${idl} is not <pkg>/msg/<Type>.idl "
                          "relative to IDL_ROOT ${idl_root}")
    endif()
    set(PKG ${CMAKE_MATCH_1})
    set(TYPE ${CMAKE_MATCH_2})
    set(DIR ${PKG}/msg)
    # The header's name as rosidl makes it: an underscore before a capital that starts a word
    # (TFMessage -> tf_message) and before one that follows a small letter or digit.
    string(REGEX REPLACE "(.)([A-Z][a-z]+)" "\\1_\\2" SNAKE ${TYPE})
    string(REGEX REPLACE "([a-z0-9])([A-Z])" "\\1_\\2" SNAKE ${SNAKE})
    string(TOLOWER ${SNAKE} SNAKE)
    set(IDL ${idl})

    set(out ${generated}/${DIR}/${TYPE})
    add_custom_command(
      OUTPUT ${out}.h ${out}.cxx ${out}PubSubTypes.h ${out}PubSubTypes.cxx ${out}.idl.inc
      COMMAND ${CMAKE_COMMAND} -DFASTDDSGEN=${FASTDDSGEN} "-DINCLUDE_DIRS=${include_dirs}"
              -DIDL_ROOT=${idl_root} -DIDL=${idl} -DOUT=${generated}
              -P ${_MOCAP_MESSAGES_CMAKE_DIR}/generate_idl.cmake
      DEPENDS ${idl_paths} ${_MOCAP_MESSAGES_CMAKE_DIR}/generate_idl.cmake
      COMMENT "fastddsgen ${idl}"
      VERBATIM)
    configure_file(${templates}/message.hpp.in ${generated}/${DIR}/${SNAKE}.hpp @ONLY)
    configure_file(${templates}/message_type.cpp.in
                   ${generated}/type_support/${PKG}_${SNAKE}.cpp @ONLY)
    list(APPEND type_sources ${out}.cxx)
    list(APPEND support_sources ${generated}/type_support/${PKG}_${SNAKE}.cpp)
    list(APPEND dds_sources ${out}PubSubTypes.cxx)
    list(APPEND classes ${PKG}::msg::${TYPE})
    list(APPEND headers ${DIR}/${SNAKE}.hpp)
  endforeach()
  # fastddsgen's classes, with warnings off (not our code to keep warning-free), compiled as
  # unity files like the type supports: each type's file is small and its headers are the same,
  # so one compile parses Fast CDR and the standard headers for several types.
  add_library(${target}_classes OBJECT ${type_sources})
  target_compile_options(${target}_classes PRIVATE -w)
  target_include_directories(${target}_classes SYSTEM PRIVATE ${generated})
  target_link_libraries(${target}_classes PRIVATE fastcdr ${dependency_targets})
  if(TARGET mocap_graph::messages)
    target_link_libraries(${target}_classes PRIVATE mocap_graph::messages)
  endif()
  set_target_properties(${target}_classes PROPERTIES UNITY_BUILD ON POSITION_INDEPENDENT_CODE ON)
  add_library(${target} SHARED $<TARGET_OBJECTS:${target}_classes> ${support_sources})
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON)
  target_include_directories(${target} SYSTEM PUBLIC $<BUILD_INTERFACE:${generated}>)
  target_link_libraries(${target} PUBLIC mocap_graph::runtime fastcdr ${dependency_targets})
  set_target_properties(${target} PROPERTIES MOCAP_IDL_ROOT ${idl_root})
  if(TARGET mocap_graph::messages)
    target_link_libraries(${target} PUBLIC mocap_graph::messages)
  endif()
  if(NOT PROJECT_NAME STREQUAL "mocap_graph")
    set_target_properties(${target} PROPERTIES
      OUTPUT_NAME mocap_messages_${target}
      LIBRARY_OUTPUT_DIRECTORY ${MOCAP_PLUGIN_OUTPUT_DIRECTORY}
      INSTALL_RPATH "${MOCAP_PLUGIN_INSTALL_RPATH}")
    install(TARGETS ${target} LIBRARY DESTINATION ${MOCAP_PLUGIN_INSTALL_DIRECTORY})
  endif()
  set(${target}_CLASSES ${classes} PARENT_SCOPE)
  set(${target}_HEADERS ${headers} PARENT_SCOPE)
  set(${target}_DDS_SOURCES ${dds_sources} PARENT_SCOPE)
endfunction()
