// Tile binning: for each 8x8 pixel tile (measured against 16x16: the backward pass of
// tiger and boston twice as fast, the forward pass the same), the draws that can reach it, in paint order,
// each with the few segments that matter inside the tile.
//
// The winding number of a fill at a sample p in tile region R (the tile grown by how far
// its samples and prefilter reach) is counted along a path from p to infinity that
// stays in R until R's top-right corner C: p -> (R.x1, p.y) -> C, then the ray from C
// towards +x. The ray from C is shared by every sample of the tile, so its crossings
// are counted once per tile (the entry's `winding`); only segments inside R can cross
// the two short legs. Crossings of the vertical leg do not depend on p either, except
// through its length, so they are stored per (segment, tile) as heights.
//
// Conventions, equivalent to moving the path by an infinitesimal (+e, +e): horizontal
// lines count pieces on [y_low, y_high); the vertical leg at x = R.x1 counts x-monotone
// pieces on [x_low, x_high) with crossing height in (R.y0, p.y]; leg 1 counts crossings
// with p.x < x <= R.x1 and the corner ray those with x > R.x1.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/coverage.h"
#include "scene/scene.h"

namespace vf {

constexpr int TILE = 8;

// A fill segment's crossings of a tile's vertical leg (x = region.x1): heights and directions.
struct LegCrossings {
    double y[3] = {0, 0, 0};
    int8_t dir[3] = {0, 0, 0};
    int8_t n = 0;
};

struct LocalItem {
    int32_t item = 0;             // index into the draw's fill or stroke items
    int32_t cross = -1;           // fills: its crossings of the vertical leg (index into the
                                  // bins' crossings), -1 where it has none (most items)
    // The segment's heights (its box's, as floats rounded outwards; for a stroke its
    // piece's, half width included): a ray at a height outside them crosses nothing, and a
    // stroke's piece lies farther than the height difference, so the segment itself (384
    // bytes, scattered) need not be read. Most of a tile's segments are set aside so, per
    // sample.
    float y0 = 0, y1 = -1;
    float x0 = 0, x1 = -1;        // strokes: the piece's box's sides, as the heights
    VF_HD bool spans(double y) const { return y >= y0 && y <= y1; }
};

struct TileEntry {
    int32_t draw = 0;
    int32_t winding = 0;          // fills: crossings of the corner ray; strokes: 1 where the
                                  // tile's region lies inside one piece of the stroke (then
                                  // it is covered there, and no items are listed)
    int32_t first = 0, count = 0; // local items
};

// The bins as the per-sample code reads them (host or device memory).
struct TileView {
    int nx = 0, ny = 0;
    double margin = 0;
    Span<int> start;
    Span<TileEntry> entries;
    Span<LocalItem> items;
    Span<LegCrossings> crossings;
    // The vertical leg's crossings of an item at heights up to y (see tile_winding).
    VF_HD int leg_crossings(const LocalItem& li, double y) const {
        if (li.cross < 0) return 0;
        const LegCrossings& c = crossings[li.cross];
        int w = 0;
        for (int k = 0; k < c.n; ++k)
            if (c.y[k] <= y) w += c.dir[k];  // heights are already > region.y0
        return w;
    }
    VF_HD const TileEntry* begin(int tile) const { return entries.data() + start[tile]; }
    VF_HD int count(int tile) const { return start[tile + 1] - start[tile]; }
    VF_HD Box region(int tile) const {  // pixel-space area the tile's samples and prefilter reach
        int tx = tile % nx, ty = tile / nx;
        return {tx * (double)TILE - margin, ty * (double)TILE - margin, (tx + 1) * (double)TILE + margin,
                (ty + 1) * (double)TILE + margin};
    }
};

struct TileBins {
    int nx = 0, ny = 0;
    double margin = 0;
    std::vector<int> start;       // [nx * ny + 1] offsets into entries
    std::vector<TileEntry> entries;
    std::vector<LocalItem> items;
    std::vector<LegCrossings> crossings;
    TileView view() const {
        return {nx, ny, margin, span_of(start), span_of(entries), span_of(items), span_of(crossings)};
    }
    Box region(int tile) const { return view().region(tile); }
};

// Index of sample s (of spp per pixel) of pixel (x, y) among its tile's samples: pixel by
// pixel, in rows, then the pixel's own order.
VF_HD int tile_sample(int x, int y, int width, int spp, int s) {
    int x0 = x / TILE * TILE, y0 = y / TILE * TILE, w = vmin(width - x0, TILE);
    return ((y - y0) * w + (x - x0)) * spp + s;
}

// Signed distances of some of a tile's fill entries at every sample of the tile, computed
// ahead segment by segment (scene/field.h, the CPU's analytical passes): what entry_sdf
// gives there, and its SdfArg. The GPU and the other passes have none (a null view).
struct FieldView {
    const int* slot = nullptr;    // per entry of the tile (its place in the tile's list): its field, or -1
    const double* sd = nullptr;   // [slot * n + sample]
    const SdfArg* arg = nullptr;  // the same layout, or null (forward pass)
    int n = 0;                    // samples in the tile
    int tile = -1;                // the tile
    VF_HD bool has(int k) const { return slot && slot[k] >= 0; }
    VF_HD double sd_at(int k, int sample) const { return sd[(size_t)slot[k] * n + sample]; }
    VF_HD const SdfArg& arg_at(int k, int sample) const { return arg[(size_t)slot[k] * n + sample]; }
};

// margin: how far (pixels) outside a tile its samples and their prefilter reach.
// With every_tile, a draw gets an entry in every tile its bounds reach (no culling of
// tiles it cannot cover): the brute-force check of the tiles uses that. threads: how
// many threads bin the draws (0: all cores); the bins do not depend on it.
TileBins bin_draws(const PreparedScene& scene, int width, int height, double margin, bool every_tile = false,
                   int threads = 1);

// Winding number of a fill draw at p in the tile, from its entry (see above).
VF_HD int tile_winding(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region, Vec2 p) {
    const PreparedDraw& d = sc.draws[e.draw];
    const PreparedSegment* segs = sc.fill_items.data() + d.first_item;
    const LocalItem* items = bins.items.data() + e.first;
    int w = e.winding;
    for (int i = 0; i < e.count; ++i) {
        const LocalItem& li = items[i];
        if (li.spans(p.y)) w += ray_crossings(segs[li.item], p, region.x1);
        w += bins.leg_crossings(li, p.y);
    }
    return w;
}

// The items a tile entry lists, as the coverage queries take them (see AllItems).
struct LocalItems {
    const LocalItem* li;
    int n;
    VF_HD LocalItems(const TileView& bins, const TileEntry& e) : li(bins.items.data() + e.first), n(e.count) {}
    VF_HD int size() const { return n; }
    VF_HD int operator[](int i) const { return li[i].item; }
    // Whether item i's box (a stroke's) may come within `reach` of p (see LocalItem::y0).
    VF_HD bool may_reach(int i, Vec2 p, double reach) const {
        const LocalItem& l = li[i];
        return p.y >= l.y0 - reach && p.y <= l.y1 + reach && p.x >= l.x0 - reach && p.x <= l.x1 + reach;
    }
    // Whether item i may come below sd (stroke space, q): no bound here (see field.h's).
    VF_HD bool may_beat(int, Vec2, double) const { return true; }
};

// Whether the entry's draw covers p (a point of the tile region): the Monte Carlo test.
VF_HD bool entry_covers(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region, Vec2 p) {
    const PreparedDraw& d = sc.draws[e.draw];
    if (d.kind == DRAW_STROKE) return e.winding != 0 || stroke_contains(sc, d, LocalItems(bins, e), p);
    if (d.is_ellipse) return ellipse_contains(d.ellipse, p);
    return winding_inside(tile_winding(sc, bins, e, region, p), d.fill_rule);
}

// Signed distance from p to the entry's draw (negative inside; searched within r): what
// the analytical prefilter's coverage is made from. `arg`, if given, says where the
// closest point lies, for the derivatives.
VF_HD double entry_sdf(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region, Vec2 p,
                       double r, SdfArg* arg = nullptr) {
    const PreparedDraw& d = sc.draws[e.draw];
    if (d.kind == DRAW_STROKE) {
        if (e.winding != 0) {  // inside by at least the region's margin, which is >= r
            if (arg) arg->kind = SdfArg::NONE;
            return -r;
        }
        return stroke_sdf(sc, d, LocalItems(bins, e), p, r, arg);
    }
    if (d.is_ellipse) return ellipse_fill_sdf(d, p, r, arg);
    double dist = fill_distance(sc, d, LocalItems(bins, e), p, r, arg);
    return winding_inside(tile_winding(sc, bins, e, region, p), d.fill_rule) ? -dist : dist;
}

// For a fill hit within ON_EDGE of its closest segment: which side of the segment (along
// its left normal at arg.t) is inside, from the winding numbers just off the edge (see
// SdfArg::side). Rare: only where a sample lies on an edge.
VF_HD int entry_inside_side(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region,
                            const SdfArg& arg) {
    const PreparedDraw& d = sc.draws[e.draw];
    Vec2 tangent = seg_deriv(sc.fill_items[arg.item].seg, arg.t);
    double speed = length(tangent);
    if (speed <= 0) return 0;
    Vec2 n = (10 * ON_EDGE / speed) * perp(tangent);
    bool plus = winding_inside(tile_winding(sc, bins, e, region, arg.closest + n), d.fill_rule);
    bool minus = winding_inside(tile_winding(sc, bins, e, region, arg.closest - n), d.fill_rule);
    return plus == minus ? 0 : (plus ? 1 : -1);
}

}  // namespace vf
