# mocap_generate_messages(<target> IDL_FILES <pkg/msg/Type.idl>... [IDL_ROOT <dir>]
#                         [INCLUDE_DIRS <dirs>...])
#
# Makes the shared library <target> of message types from IDL files laid out as ROS 2's are
# (<pkg>/msg/<Type>.idl, module <pkg> { module msg { struct <Type> ... } }), relative to
# IDL_ROOT (default: the current source directory). For each type it runs fastddsgen (the C++
# class, XCDR1 serialization) and adds, in ROS 2's layout, <pkg>/msg/<type>.hpp, the header
# components include, and the runtime's type support: components publish and subscribe the
# type, and mocap_topic echo, mocap_bag and any DDS peer see it as pkg/msg/Type, DDS type
# pkg::msg::dds_::Type_. The Cyclone DDS backend carries the same XCDR1 bytes through the
# runtime's own type support, so no second generator runs.
#
# IDL files may include the shipped messages (#include "geometry_msgs/msg/Pose.idl"): the
# shipped IDL directory is on the include path, and <target> links mocap_graph::messages.
#
# Outside this repository the library is named libmocap_messages_<target>.so and goes beside
# your plugins (MOCAP_PLUGIN_OUTPUT_DIRECTORY; installed: lib/mocap_graph/plugins), where
# mocap_topic and mocap_bag load every libmocap_messages_*.so so that they know your types.
# Sets in the caller's scope, one entry per IDL file: <target>_CLASSES (pkg::msg::Type),
# <target>_HEADERS (pkg/msg/type.hpp) and <target>_DDS_SOURCES (fastddsgen's Fast DDS type
# supports, for programs that use Fast DDS directly).
include_guard(GLOBAL)
include(${CMAKE_CURRENT_LIST_DIR}/MocapAddPlugin.cmake)

set(_MOCAP_MESSAGES_CMAKE_DIR ${CMAKE_CURRENT_LIST_DIR})
if(NOT FASTDDSGEN)
  find_program(FASTDDSGEN fastddsgen REQUIRED)
endif()

function(mocap_generate_messages target)
  cmake_parse_arguments(ARG "" "IDL_ROOT" "IDL_FILES;INCLUDE_DIRS" ${ARGN})
  if(NOT ARG_IDL_FILES)
    message(FATAL_ERROR "mocap_generate_messages(${target}): no IDL_FILES")
  endif()
  if(NOT ARG_IDL_ROOT)
    set(ARG_IDL_ROOT ${CMAKE_CURRENT_SOURCE_DIR})
  endif()
  get_filename_component(idl_root ${ARG_IDL_ROOT} ABSOLUTE)
  set(include_dirs ${idl_root} ${ARG_INCLUDE_DIRS})
  if(DEFINED MOCAP_GRAPH_IDL_DIR)
    list(APPEND include_dirs ${MOCAP_GRAPH_IDL_DIR})
  endif()
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
    if(NOT EXISTS ${idl_root}/${idl})
      message(FATAL_ERROR "mocap_generate_messages(${target}): ${idl_root}/${idl} does not exist")
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
    file(READ ${idl_root}/${idl} IDL_TEXT)

    set(out ${generated}/${DIR}/${TYPE})
    add_custom_command(
      OUTPUT ${out}.h ${out}.cxx ${out}PubSubTypes.h ${out}PubSubTypes.cxx
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
  # fastddsgen's code is not ours to keep warning-free.
  set_source_files_properties(${type_sources} ${dds_sources} PROPERTIES COMPILE_OPTIONS "-w")

  add_library(${target} SHARED ${type_sources} ${support_sources})
  target_include_directories(${target} SYSTEM PUBLIC $<BUILD_INTERFACE:${generated}>)
  target_link_libraries(${target} PUBLIC mocap_graph::runtime fastcdr)
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
