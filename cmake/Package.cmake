# `cpack -G DEB` (in the build folder) -> mocap-graph_<version>_amd64.deb: everything
# cmake --install puts in a prefix, under /usr. One package holds the tools, plugins and the
# files to build your own components; Depends is computed from the binaries' shared libraries
# (dpkg-shlibdeps), and building against it needs the -dev packages that
# scripts/install_deps.sh installs.
set(CPACK_PACKAGE_NAME mocap-graph)
set(CPACK_PACKAGE_VENDOR "mocap-graph")
set(CPACK_PACKAGE_CONTACT "mocap-graph maintainers <mocap-graph@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Motion capture as a DDS component graph: tracking, PixArt, followers, calibration")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_STRIP_FILES ON)
# The plugins find the runtime through their own run path; dpkg-shlibdeps needs to know where
# this package's libraries are to skip them.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS_PRIVATE_DIRS ${CMAKE_BINARY_DIR}/lib)
# fastddsgen runs when a project of your own generates messages.
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "fastddsgen, libfastcdr-dev, libfmt-dev, libyaml-cpp-dev, libeigen3-dev")
include(CPack)
