// The forward pass's per-pixel work, shared by the CPU loop (forward.cpp) and the CUDA
// kernel: composite the draws that cover each sample front to back (stopping once it is
// opaque), with nested layers for group opacity, and filter the samples into a pixel.
// pixel_forward and sample_forward have their adjoints in backward/pixel.h
// (pixel_backward, sample_backward).
#pragma once

#include "common/sampling.h"
#include "forward/composite.h"
#include "forward/forward.h"
#include "scene/coverage.h"
#include "scene/layers.h"
#include "scene/paint.h"
#include "scene/tiles.h"

namespace vf {

// Coverage of one draw at p in [0, 1]: a step (Monte Carlo) or the prefiltered kernel,
// from the tile's entry, or, brute force, from every item of the draw.
VF_HD double entry_coverage(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region,
                            Vec2 p, const RenderOptions& o) {
    const bool analytic = o.mode == MODE_ANALYTIC;
    const double r = o.filter_radius;
    if (!o.brute_force) {
        if (analytic) return kernel_coverage(entry_sdf(sc, bins, e, region, p, r) / r);
        return entry_covers(sc, bins, e, region, p) ? 1.0 : 0.0;
    }
    const PreparedDraw& d = sc.draws[e.draw];
    if (d.is_ellipse && d.kind == DRAW_FILL) {
        if (analytic) return kernel_coverage(ellipse_fill_sdf(d, p, r) / r);
        return ellipse_contains(d.ellipse, p) ? 1.0 : 0.0;
    }
    AllItems all{d.n_items};
    if (d.kind == DRAW_STROKE) {
        if (analytic) return kernel_coverage(stroke_sdf(sc, d, all, p, r) / r);
        return stroke_contains(sc, d, all, p) ? 1.0 : 0.0;
    }
    bool inside = winding_inside(draw_winding_all(sc, d, p), d.fill_rule);
    if (!analytic) return inside ? 1.0 : 0.0;
    double dist = fill_distance(sc, d, all, p, r);
    return kernel_coverage((inside ? -dist : dist) / r);
}

// Premultiplied colour of the scene at pixel-space point p, from the tile's entries; `fields`
// (if given) holds the signed distances of some entries at the tile's samples, p being
// sample `sample` of them (see FieldView).
VF_HD void sample_forward(const SceneView& sc, const TileView& bins, int tile, Vec2 p, const RenderOptions& o,
                          double out[4], const FieldView* fields = nullptr, int sample = 0) {
    FrontToBackCompositor comp(sc);
    const TileEntry* entries = bins.begin(tile);
    Box region = bins.region(tile);
    for (int k = bins.count(tile) - 1; k >= 0; --k) {
        const TileEntry& e = entries[k];
        const PreparedDraw& d = sc.draws[e.draw];
        if (p.x < d.box.x0 - o.filter_radius || p.x > d.box.x1 + o.filter_radius ||
            p.y < d.box.y0 - o.filter_radius || p.y > d.box.y1 + o.filter_radius)
            continue;
        double coverage = fields && fields->has(k) ? kernel_coverage(fields->sd_at(k, sample) / o.filter_radius)
                                                   : entry_coverage(sc, bins, e, region, p, o);
        if (coverage <= 0) continue;
        double c[4];
        paint_color(sc, sc.paints[d.paint], p, c);
        if (c[3] <= 0) continue;
        comp.enter(d.layer);
        comp.under(c, coverage);
        if (comp.opaque()) break;
    }
    comp.finish(out);
}

// A pixel's filtered premultiplied colour (acc / wsum), the background under it, written
// as straight RGBA (or premultiplied, where the options ask for it).
VF_HD void pixel_output(const double acc[4], double wsum, const double bg[4], float* px, bool premultiplied = false) {
    double k = wsum > 0 ? 1 / wsum : 0, c[4];
    for (int i = 0; i < 4; ++i) c[i] = acc[i] * k;
    double rest = 1 - c[3];
    for (int i = 0; i < 4; ++i) c[i] += rest * bg[i];
    double a = c[3];
    if (premultiplied) {
        for (int i = 0; i < 4; ++i) px[i] = (float)vclamp(c[i], 0.0, 1.0);
        return;
    }
    for (int i = 0; i < 3; ++i) px[i] = a > 0 ? (float)vclamp(c[i] / a, 0.0, 1.0) : 0.0f;
    px[3] = (float)vclamp(a, 0.0, 1.0);
}

// One output pixel: its samples filtered, the background under them, as straight RGBA.
// o is the plan's options (filter radius settled); bg the premultiplied background;
// fields: the tile's precomputed entries, or null (see sample_forward).
VF_HD void pixel_forward(const SceneView& sc, const TileView& bins, const RenderOptions& o, const double bg[4], int x,
                         int y, float* px, const FieldView* fields = nullptr) {
    const int N = o.samples;
    const double R = o.filter_radius;
    int tile = (y / TILE) * bins.nx + x / TILE;
    bool any = bins.count(tile) > 0;
    double acc[4] = {0, 0, 0, 0}, wsum = 0;
    uint64_t pixel = (uint64_t)y * o.width + x;
    for (int s = 0; s < N * N; ++s) {
        double fx = ((s % N) + 0.5) / N, fy = ((s / N) + 0.5) / N;  // strata centres
        if (o.mode == MODE_MC) sample_position(o.seed, pixel, s, N, fx, fy);
        double dx = R * (2 * fx - 1), dy = R * (2 * fy - 1);
        double w = filter_weight(o.filter, R, dx, dy);
        if (w <= 0) continue;
        double c[4] = {0, 0, 0, 0};
        if (any)
            sample_forward(sc, bins, tile, {x + 0.5 + dx, y + 0.5 + dy}, o, c, fields,
                           fields ? tile_sample(x, y, o.width, N * N, s) : 0);
        for (int i = 0; i < 4; ++i) acc[i] += w * c[i];
        wsum += w;
    }
    pixel_output(acc, wsum, bg, px, o.premultiplied);
}

}  // namespace vf
