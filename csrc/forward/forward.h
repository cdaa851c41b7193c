// Forward rendering of a prepared scene into a straight-RGBA float image; and the render
// options, which the backward pass takes too.
#pragma once

#include <cstdint>

#include "scene/scene.h"
#include "scene/tiles.h"

namespace vf {

enum Mode : int { MODE_MC = 0, MODE_ANALYTIC = 1 };

struct RenderOptions {
    int width = 0, height = 0;
    int samples = 2;            // samples x samples per pixel
    int mode = MODE_MC;
    int filter = 0;             // FilterKind
    double filter_radius = 0.5; // support half-width in pixels; also the analytic kernel radius
    uint64_t seed = 0;
    int threads = 0;            // 0: all cores
    // Monte Carlo backward only: how many of a pixel's samples x samples the interior term
    // revisits (0: all). Fewer, chosen at random and weighted up, keep it unbiased.
    int interior_samples = 0;
    // Monte Carlo backward only: at most about this many boundary samples per pixel of the
    // image in all (0: no bound). Past it the samples go to the boundary pieces by their
    // length times the pixel adjoints near them (backward.cpp, boundary_pieces), so a
    // dense scene's boundary term costs what its pixels cost, not what its outlines do.
    double boundary_budget = 0;
    bool brute_force = false;   // test every item of every draw (a check of the tiles)
    bool has_background = false;
    double background[4] = {0, 0, 0, 0};  // straight RGBA
    // The image as premultiplied RGBA instead of straight (for layers that Python
    // composites: clip paths, masks, filters); the backward pass then takes dL/d(that).
    bool premultiplied = false;
};

// The options as both passes use them: at least one sample, and the filter radius settled
// (the box filter covers exactly the pixel; the others reach at least that far).
RenderOptions settled(const RenderOptions& options);
// The background, clamped and premultiplied (zero without one).
void premultiplied_background(const RenderOptions& options, double out[4]);

// What the per-pixel work needs besides the scene: the options with the filter radius
// settled, the tiles, and the premultiplied background.
struct ForwardPlan {
    RenderOptions options;
    TileBins bins;
    double background[4] = {0, 0, 0, 0};
};
ForwardPlan plan_forward(const PreparedScene& scene, const RenderOptions& options);

// out: height x width x 4 floats, straight (not premultiplied) RGBA.
void render_forward(const PreparedScene& scene, const RenderOptions& options, float* out);

// dL/d(filter radius) in Monte Carlo mode (see filter_radius_kernel, common/sampling.h),
// given pixels, the image as rendered, and g, dL/d(it): both height x width x 4, each
// pixel's filtered premultiplied colour with the background excluded. 0 for the box filter
// (its radius is fixed) and below 0.5 px (settled to 0.5).
double filter_radius_gradient(const PreparedScene& scene, const RenderOptions& options, const float* pixels,
                              const float* g);

}  // namespace vf
