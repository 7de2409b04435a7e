// fastddsgen's own Fast DDS type support for every type of idl/: for programs that use Fast
// DDS directly, such as the raw Fast DDS benchmark reference and wire-compatibility tests.
#pragma once

#include <memory>
#include <vector>

#include <fastdds/dds/topic/TopicDataType.hpp>

namespace mocap {

std::vector<std::unique_ptr<eprosima::fastdds::dds::TopicDataType>> generated_dds_type_supports();

}  // namespace mocap
