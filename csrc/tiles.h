// Tile binning: for each 16x16 pixel tile, the draws whose bounds reach it, in paint
// order, so that a sample only looks at what can cover it.
#pragma once

#include <vector>

#include "scene.h"

namespace vf {

constexpr int TILE = 16;

struct TileBins {
    int nx = 0, ny = 0;
    std::vector<int> start;  // [nx * ny + 1] offsets into draws
    std::vector<int> draws;
    const int* begin(int tile) const { return draws.data() + start[tile]; }
    int count(int tile) const { return start[tile + 1] - start[tile]; }
};

// margin: how far (pixels) outside a tile its samples and their prefilter reach.
TileBins bin_draws(const PreparedScene& scene, int width, int height, double margin);

}  // namespace vf
