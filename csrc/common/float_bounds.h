// A double range's ends as floats, rounded outwards: what the prepared segments and the
// tile items store of a range, so that no float range is narrower than the exact one.
#pragma once

#include <cmath>

namespace vf {

inline float float_below(double v) {
    float f = (float)v;
    return (double)f > v ? std::nextafter(f, -INFINITY) : f;
}

inline float float_above(double v) {
    float f = (float)v;
    return (double)f < v ? std::nextafter(f, INFINITY) : f;
}

}  // namespace vf
