// Per-point work on the tracer's outline stretches and loops (vecfit/initial/tracer/
// bezier.py's Stretches, Loops, find_corners and _medians): open polylines laid end to end, each given by its first
// point and length.
#pragma once

#include <cstdint>
#include <vector>

namespace vf {

// Each stretch smoothed with `kernel` (2r + 1 weights), extended past its ends by point
// reflection, its end points held: [M, 2].
std::vector<double> smooth_stretches(const double* points, int64_t count, const int64_t* first,
                                     const int64_t* lengths, const double* kernel, int64_t kernel_size);

// The unit forward tangent at each point, from the points `window` away along its
// stretch (one-sided near the ends; (1, 0) where they coincide): [M, 2].
std::vector<double> stretch_tangents(const double* points, int64_t count, const int64_t* first,
                                     const int64_t* lengths, int64_t window);

// Closed loops (laid end to end the same way): each smoothed with the kernel of its
// reach r (kernels: all kernels end to end, kernel_at[r] where r's 2r + 1 weights begin;
// reach 0 leaves a loop as it is), wrapping round the loop: [M, 2].
std::vector<double> smooth_loops(const double* points, int64_t count, const int64_t* first, const int64_t* lengths,
                                 const int64_t* reach, const double* kernels, const int64_t* kernel_at);

// For each point of the loops, the least value within `window` places either side
// along its loop (NaN if any is NaN, as np.minimum has it).
std::vector<double> loop_window_min(const double* values, int64_t count, const int64_t* first,
                                    const int64_t* lengths, int64_t window);

// The median (np.median's: the mean of the middle two of an even count) of the valid
// values of each wanted group (groups 0..groups-1), in group order, for groups with at
// least one valid value.
std::vector<double> group_medians(const double* values, const int64_t* group, const uint8_t* valid, int64_t n,
                                  const uint8_t* wanted, int64_t groups);

}  // namespace vf
