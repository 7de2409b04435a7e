# The tree's include graph, floor by floor: which floor includes which, how often, and every
# include that runs from a lower floor up to a higher one, or from one DDS implementation into
# another. Any such include fails the check.
#
#   cmake -DSOURCE_DIR=. -P scripts/include_floors.cmake
#
# Prints one line per pair of floors ("host -> dds: 9 includes") and one line per wrong include
# ("runtime/src/core/x.cpp:3: core includes host: runtime/src/host/y.hpp"), and exits 1 when
# there is any. ctest runs it (IncludeFloors). A floor may include its own and every floor below.
cmake_minimum_required(VERSION 3.25)
if(NOT SOURCE_DIR)
  message(FATAL_ERROR "usage: cmake -DSOURCE_DIR=<repository> -P include_floors.cmake")
endif()
get_filename_component(root "${SOURCE_DIR}" ABSOLUTE)

# Bottom to top. The runtime knows nothing of motion capture; components know nothing of DDS.
set(floors api messages core transport dds dds_implementation host launch message_support bag
           calibration common components tools tests)
set(folders_api runtime/include)                  # the component API, installed
set(folders_messages runtime/src/messages)        # message types at run time: schemas, CDR
set(folders_core runtime/src/core)                # executor, timers, names, parameters, logs
set(folders_transport runtime/src/transport)      # the Transport interface, in-process delivery
set(folders_dds runtime/src/dds)                  # what every DDS implementation shares
set(folders_dds_implementation)                   # runtime/src/dds/<name>/: each one alone
set(folders_host runtime/src/host)                # component host, contexts, plugins, DDS table
set(folders_launch runtime/src/launch)            # launch files, the group supervisor
set(folders_message_support idl)                  # the messages' support (generated code's)
set(folders_bag bag)                              # the bag library
set(folders_calibration calibration)              # camera models and the calibration
set(folders_common components/common)             # what several components share
set(folders_components components)                # algorithm libraries and plugins
set(folders_tools tools)                          # the programs
set(folders_tests test bench fuzz examples)       # above everything

# Where an include is looked for, after the including file's own folder.
set(include_roots runtime/src components tools . bag/src runtime/include bag/include
                  calibration/include idl/support/include idl)

# The floor of `path` (relative to the root) in `out_floor`, its index in `out_index`, and for a
# DDS implementation its folder in `out_part`; "" when no floor holds it.
function(floor_of path out_floor out_index out_part)
  set(best "")
  set(best_length 0)
  set(part "")
  if(path MATCHES "^runtime/src/dds/([^/]+)/")
    set(best dds_implementation)
    set(best_length 1000)
    set(part ${CMAKE_MATCH_1})
  endif()
  foreach(floor IN LISTS floors)
    foreach(folder IN LISTS folders_${floor})
      string(LENGTH "${folder}/" length)
      string(SUBSTRING "${path}" 0 ${length} head)
      if(head STREQUAL "${folder}/" AND length GREATER best_length)
        set(best ${floor})
        set(best_length ${length})
      endif()
    endforeach()
  endforeach()
  list(FIND floors "${best}" index)
  set(${out_floor} "${best}" PARENT_SCOPE)
  set(${out_index} ${index} PARENT_SCOPE)
  set(${out_part} "${part}" PARENT_SCOPE)
endfunction()

set(sources)
foreach(top runtime idl bag calibration components tools test bench fuzz examples)
  file(GLOB_RECURSE found RELATIVE "${root}" "${root}/${top}/*.cpp" "${root}/${top}/*.hpp"
       "${root}/${top}/*.h")
  list(APPEND sources ${found})
endforeach()

set(problems 0)
set(edges)
foreach(source IN LISTS sources)
  floor_of("${source}" from from_index from_part)
  if(from STREQUAL "")
    continue()
  endif()
  get_filename_component(folder "${source}" DIRECTORY)
  file(STRINGS "${root}/${source}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<]")
  set(line_number 0)
  foreach(line IN LISTS lines)
    string(REGEX MATCH "#[ \t]*include[ \t]*([\"<])([^\">]+)[\">]" _ "${line}")
    set(quoted "${CMAKE_MATCH_1}")
    set(name "${CMAKE_MATCH_2}")
    set(target "")
    foreach(base IN ITEMS ${folder} ${include_roots})
      if(EXISTS "${root}/${base}/${name}" AND NOT IS_DIRECTORY "${root}/${base}/${name}")
        file(RELATIVE_PATH target "${root}" "${root}/${base}/${name}")
        break()
      endif()
    endforeach()
    if(target STREQUAL "" AND quoted STREQUAL "\"")
      # A file of the tree is included by its path from a root, so that the include says where
      # it is and this check can place it.
      message("${source}: \"${name}\" is found from no root (${include_roots}) nor beside it")
      math(EXPR problems "${problems} + 1")
      continue()
    elseif(target STREQUAL "")
      continue()  # a system or generated header
    endif()
    floor_of("${target}" to to_index to_part)
    if(to STREQUAL "")
      continue()
    endif()
    list(APPEND edges "${from} -> ${to}")
    if(to_index GREATER from_index)
      message("${source}: ${from} includes ${to}: ${target} (\"${name}\")")
      math(EXPR problems "${problems} + 1")
    elseif(from STREQUAL "dds_implementation" AND to STREQUAL "dds_implementation"
           AND NOT from_part STREQUAL to_part)
      message("${source}: DDS implementation ${from_part} includes ${to_part}: ${target}")
      math(EXPR problems "${problems} + 1")
    endif()
  endforeach()
endforeach()

# The graph: each pair of floors once, with how many includes join them, top floors first.
list(LENGTH sources file_count)
list(REVERSE floors)
foreach(from IN LISTS floors)
  set(line "")
  foreach(to IN LISTS floors)
    set(joining ${edges})
    list(FILTER joining INCLUDE REGEX "^${from} -> ${to}$")
    list(LENGTH joining count)
    if(count GREATER 0)
      string(APPEND line " ${to} ${count},")
    endif()
  endforeach()
  if(NOT line STREQUAL "")
    string(REGEX REPLACE ",$" "" line "${line}")
    message("${from} includes:${line}")
  endif()
endforeach()
if(problems GREATER 0)
  message(FATAL_ERROR "${problems} wrong include(s) in ${file_count} files")
endif()
message("no include from a lower floor to a higher one, in ${file_count} files")
