// Sub-pixel edges of the tracer's outlines (vecfit/initial/tracer/subpixel.py): each
// visible pixel edge moved to where the target's anti-aliasing says the edge lies.
#pragma once

#include <cstdint>
#include <vector>

namespace vf {

// The placement's settings (Python binds this struct as _core.SubpixelOptions; subpixel.py
// sets them).
struct SubpixelOptions {
    double min_contrast = 0.1, max_shift = 0.5;
    int reach = 2;
};

struct SubpixelInput {
    int64_t points = 0;
    const double* xy = nullptr;        // [points, 2] the outlines laid end to end
    int64_t outlines = 0;
    const int64_t* lengths = nullptr;  // [outlines]
    const int64_t* region = nullptr;   // [outlines] the region each outline draws
    const uint8_t* hole = nullptr;     // [outlines] whether it bounds a hole cut out of it
    int64_t width = 0, height = 0;
    const int32_t* labels = nullptr;   // [height, width] region of each pixel, -1: none
    int64_t regions = 0;
    const int64_t* rank = nullptr;     // [regions] drawing rank
    const double* colors = nullptr;    // [regions, 3] fill colours
    const float* rgb = nullptr;        // [height, width, 3] the target
    const float* alpha = nullptr;      // [height, width]
    SubpixelOptions options;
};

// The points moved ([points, 2]).
std::vector<double> refine_outlines(const SubpixelInput& in);

}  // namespace vf
