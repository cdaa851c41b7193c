// Greedy merging of the regions of a traced image (vecfit/initial/tracer/regions.py):
// the cheapest merge by Ward's criterion, one at a time, on the regions' adjacency graph.
#pragma once

#include <cstdint>
#include <vector>

namespace vf {

struct MergeInput {
    int64_t count = 0;             // regions
    const double* area = nullptr;  // [count] pixels
    const double* sums = nullptr;  // [count, 3] colour sums (mean colour x area)
    const uint8_t* thin = nullptr; // [count] one-pixel slivers that must merge
    int64_t edges = 0;
    const int64_t* pairs = nullptr;  // [edges, 2] (a < b), sorted: neighbours in ascending order
    double min_area = 0;
    int64_t budget = 0;
};

struct MergeResult {
    std::vector<int64_t> parent;  // the region each was merged into, -1 where dropped, itself if kept
    std::vector<uint8_t> alive;   // kept regions
};

// Merges until nothing must merge any more (specks under min_area, thin regions) and at
// most `budget` regions are left; see regions.py's merge_regions for the rules.
MergeResult merge_regions(const MergeInput& in);

}  // namespace vf
