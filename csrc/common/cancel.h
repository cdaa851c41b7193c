// A request to stop the work in progress (the Python binding sets it on Ctrl-C): the
// thread pool skips the tasks not yet started, and the caller throws the result away.
// The core knows nothing of who asks.
#pragma once

#include <atomic>

namespace vf {

inline std::atomic<bool>& cancel_requested() {
    static std::atomic<bool> flag{false};
    return flag;
}

}  // namespace vf
