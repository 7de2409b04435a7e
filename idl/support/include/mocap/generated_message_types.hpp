// The message types of idl/, all in one list.
#pragma once

#include <vector>

#include <mocap/message_type.hpp>

namespace mocap {

// Every type generated from idl/. Calling it also guarantees that the message library is
// loaded, so its types are registered for find_message_type().
const std::vector<const MessageType*>& generated_message_types();

}  // namespace mocap
