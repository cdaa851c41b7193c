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

// Checked by the pool between tasks and by loops whose tasks are long (a row of pixels,
// a boundary piece): a pathological tile can take seconds.
inline bool cancelled() { return cancel_requested().load(std::memory_order_relaxed); }

}  // namespace vf
