# `cpack -G DEB` (in the build folder) -> three packages, each what one kind of user installs:
#
#   mocap-graph_<version>_amd64.deb         the tools, runtime and message libraries, every
#                                           plugin but camera_source, config/ and launch_yaml/
#   mocap-graph-camera_<version>_amd64.deb  real cameras and image files: the camera_source
#                                           plugin (V4L2, video files, image folders) and
#                                           mocap_calibrate (chessboard images)
#   mocap-graph-dev_<version>_amd64.deb     headers, calibration archives, IDL files and
#                                           find_package(mocap_graph): your own components
#
# Why camera is apart: Debian's OpenCV video and image-file modules bring FFmpeg, GStreamer and
# GDAL, about 400 MB installed, which a host that only tracks, computes poses or follows never
# loads (the container image installs mocap-graph alone). Depends is computed from each
# package's binaries (dpkg-shlibdeps); camera and dev depend on mocap-graph of the same version.
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

set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime camera dev)
set(CPACK_DEBIAN_ENABLE_COMPONENT_DEPENDS ON)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME mocap-graph)
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION
    "Motion capture as a DDS component graph: tracking, PixArt, followers, calibration
 The tools (mocap_launch, mocap_topic, mocap_bag, mocap_calibration_record), the runtime and
 message libraries, every shipped plugin but camera_source, and the shipped configuration and
 launch files in /usr/share/mocap_graph.")
set(CPACK_DEBIAN_CAMERA_PACKAGE_NAME mocap-graph-camera)
set(CPACK_COMPONENT_CAMERA_DEPENDS runtime)
set(CPACK_COMPONENT_CAMERA_DESCRIPTION
    "mocap-graph: real cameras and image files
 The camera_source plugin (V4L2 devices, video files, folders of images) and mocap_calibrate
 (camera calibration from chessboard images), with OpenCV's video and image-file modules.")
set(CPACK_DEBIAN_DEV_PACKAGE_NAME mocap-graph-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_COMPONENT_DEV_DEPENDS runtime)
set(CPACK_COMPONENT_DEV_DESCRIPTION
    "mocap-graph: build your own components and messages
 Headers (component API, messages, camera models, calibration, bags), the calibration archives,
 the shipped messages (IDL and ROS 2 .msg files) and the CMake package: find_package(mocap_graph),
 mocap_add_plugin, mocap_generate_messages (with mocap_msg_to_idl for .msg files).")
# What find_package(mocap_graph) finds (cmake/mocap_graphConfig.cmake.in) and fastddsgen, which
# mocap_generate_messages runs.
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "cmake, g++, fastddsgen, libfastcdr-dev, libfastrtps-dev, libfmt-dev, libyaml-cpp-dev, libeigen3-dev, nlohmann-json3-dev, libceres-dev, libopencv-dev")
include(CPack)
