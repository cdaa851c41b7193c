#include "tiles.h"

#include <algorithm>
#include <cmath>

namespace vf {

TileBins bin_draws(const PreparedScene& scene, int width, int height, double margin) {
    TileBins bins;
    bins.nx = (width + TILE - 1) / TILE;
    bins.ny = (height + TILE - 1) / TILE;
    int n_tiles = bins.nx * bins.ny;
    // Tile range of each draw, or an empty range.
    std::vector<int> range(4 * scene.draws.size());
    std::vector<int> counts(n_tiles + 1, 0);
    for (size_t i = 0; i < scene.draws.size(); ++i) {
        const Box& b = scene.draws[i].box;
        int* r = &range[4 * i];
        r[0] = r[1] = 0;
        r[2] = r[3] = -1;
        if (!valid(b)) continue;
        double x0 = std::floor((b.x0 - margin) / TILE), x1 = std::floor((b.x1 + margin) / TILE);
        double y0 = std::floor((b.y0 - margin) / TILE), y1 = std::floor((b.y1 + margin) / TILE);
        r[0] = (int)std::max(0.0, x0);
        r[1] = (int)std::max(0.0, y0);
        r[2] = (int)std::min<double>(bins.nx - 1, x1);
        r[3] = (int)std::min<double>(bins.ny - 1, y1);
        for (int ty = r[1]; ty <= r[3]; ++ty)
            for (int tx = r[0]; tx <= r[2]; ++tx) ++counts[ty * bins.nx + tx];
    }
    bins.start.assign(n_tiles + 1, 0);
    for (int t = 0; t < n_tiles; ++t) bins.start[t + 1] = bins.start[t] + counts[t];
    bins.draws.resize(bins.start[n_tiles]);
    std::vector<int> fill(bins.start.begin(), bins.start.end() - 1);
    for (size_t i = 0; i < scene.draws.size(); ++i) {
        const int* r = &range[4 * i];
        for (int ty = r[1]; ty <= r[3]; ++ty)
            for (int tx = r[0]; tx <= r[2]; ++tx) bins.draws[fill[ty * bins.nx + tx]++] = (int)i;
    }
    return bins;
}

}  // namespace vf
