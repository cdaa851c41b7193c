// Per-point work on the tracer's outline stretches (vecfit/initial/tracer/bezier.py's
// Stretches and _medians): open polylines laid end to end, each given by its first
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

// The median (np.median's: the mean of the middle two of an even count) of the valid
// values of each wanted group (groups 0..groups-1), in group order, for groups with at
// least one valid value.
std::vector<double> group_medians(const double* values, const int64_t* group, const uint8_t* valid, int64_t n,
                                  const uint8_t* wanted, int64_t groups);

}  // namespace vf
