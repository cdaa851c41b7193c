// Runs of consecutive draws of about equal work, for work done draw by draw (binning,
// boundary pieces) that threads share and then join in draw order, so that the result
// is the serial one exactly. About a dozen runs per thread even out draws of unequal
// size; a draw's work is counted as 1 + its items.
#pragma once

#include <algorithm>
#include <vector>

#include "common/thread_pool.h"
#include "scene/scene.h"

namespace vf {

// The threads to share n_draws out to: `threads` (0: all cores), at least 1, at most one
// per draw.
inline int draw_threads(int threads, int n_draws) {
    if (threads <= 0) threads = ThreadPool::hardware_threads();
    return std::max(1, std::min(threads, n_draws));
}

// Bounds of the runs (draws [b[r], b[r + 1]) form run r) for `threads` threads: one run
// for one thread.
inline std::vector<int> draw_runs(const PreparedDraw* draws, int n_draws, int threads) {
    const int n_runs = threads <= 1 ? 1 : std::max(1, std::min(n_draws, 12 * threads));
    std::vector<int> b(n_runs + 1, n_draws);
    b[0] = 0;
    size_t total = 0, done = 0;
    for (int i = 0; i < n_draws; ++i) total += 1 + draws[i].n_items;
    int r = 0;
    for (int i = 0; i < n_draws && r + 1 < n_runs; ++i) {
        done += 1 + draws[i].n_items;
        if (done * n_runs >= total * (r + 1)) b[++r] = i + 1;  // (run r closes at its share)
    }
    return b;
}

}  // namespace vf
