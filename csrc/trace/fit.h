// The tracer's Bézier fit of outline stretches (vecfit/initial/tracer/bezier.py): each
// stretch fitted by least squares with fixed end tangents, reparameterised by Newton
// steps and split at its worst point until within tolerance.
#pragma once

#include <cstdint>
#include <vector>

namespace vf {

// The fit's settings (Python binds this struct as _core.FitOptions; bezier.py sets them).
struct FitOptions {
    double tolerance = 1;
    double max_turn = 0;               // radians: a piece turning further is split, not judged
    double newton_range = 4;           // reparameterise pieces within this many tolerances
    int newton_steps = 4;
};

struct FitInput {
    const double* points = nullptr;    // [M, 2] the (smoothed) stretches laid end to end
    const double* tangents = nullptr;  // [M, 2] unit forward tangent at each point (used at splits)
    const double* heading = nullptr;   // [M] unwrapped angle of each tangent
    const double* arc = nullptr;       // [M] arc length up to each point
    int64_t stretches = 0;
    const int64_t* first = nullptr;    // [K] each stretch's first point
    const int64_t* lengths = nullptr;  // [K] its points
    const double* t1 = nullptr;        // [K, 2] tangent leaving its first point
    const double* t2 = nullptr;        // [K, 2] tangent arriving at its last, pointing back into it
    FitOptions options;
};

struct FitResult {
    std::vector<double> ctrl;    // [S, 4, 2] cubic segments, by stretch and along it
    std::vector<int64_t> owner;  // [S] each one's stretch
};

FitResult fit_stretches(const FitInput& in);

}  // namespace vf
