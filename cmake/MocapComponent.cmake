# mocap_add_plugin(NAME SOURCES <files> [LIBRARIES <targets>] [OUTPUT_DIRECTORY <dir>])
#
# Builds plugin NAME as build/lib/libmocap_plugin_NAME.so (the name launch files use).
# Only the registration symbol is exported, so plugins cannot clash with each other.
function(mocap_add_plugin name)
  cmake_parse_arguments(ARG "" "OUTPUT_DIRECTORY" "SOURCES;LIBRARIES" ${ARGN})
  set(target mocap_plugin_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE mocap_runtime mocap_messages ${ARG_LIBRARIES})
  set_target_properties(${target} PROPERTIES
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON)
  if(ARG_OUTPUT_DIRECTORY)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${ARG_OUTPUT_DIRECTORY})
  endif()
endfunction()
