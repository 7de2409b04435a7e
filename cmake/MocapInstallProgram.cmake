# mocap_install_program(TARGET [COMPONENT NAME])
#
# Installs a program of this tree into bin/ as part of COMPONENT (runtime unless said: which
# Debian package holds it, cmake/Package.cmake) and records it, so that the target building
# a package's contents (mocap_runtime_package) builds every program the package's install
# rules name: a program installed with a bare install(TARGETS) was missing from that target,
# and cpack then stopped on the absent file.
function(mocap_install_program target)
  cmake_parse_arguments(ARG "" "COMPONENT" "" ${ARGN})
  if(NOT ARG_COMPONENT)
    set(ARG_COMPONENT ${CMAKE_INSTALL_DEFAULT_COMPONENT_NAME})
  endif()
  install(TARGETS ${target} RUNTIME DESTINATION bin COMPONENT ${ARG_COMPONENT})
  set_property(GLOBAL APPEND PROPERTY MOCAP_PROGRAMS_${ARG_COMPONENT} ${target})
endfunction()
