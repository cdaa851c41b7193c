// Backward pass on the CPU: the plan (tiles, pixel adjoints, boundary pieces) and the
// lanes that run the per-sample work of backward/pixel.h over it.
#include "backward/backward.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>
#include <vector>

#include "common/cancel.h"
#include "common/phase_clock.h"
#include "common/thread_pool.h"
#include "scene/field.h"
#include "scene/draw_runs.h"

namespace vf {
namespace {

// Buffers for the pixel adjoints kept from pass to pass: a fresh 8 MB buffer (512 x 512)
// was faulted in page by page, which took longer than filling it (6 of the 9 ms of
// pixel_adjoints on kitty, 864 x 576). A few are kept, one per concurrent pass (batches).
std::mutex spare_mutex;
std::vector<std::vector<double>> spare_buffers;

std::vector<double> adjoint_buffer(size_t n) {
    std::vector<double> v;
    {
        std::lock_guard<std::mutex> lock(spare_mutex);
        if (!spare_buffers.empty()) {
            v = std::move(spare_buffers.back());
            spare_buffers.pop_back();
        }
    }
    if (v.capacity() < n) v = std::vector<double>();  // (not copied over into a bigger one)
    v.resize(n);  // every element is written by pixel_adjoints
    return v;
}

void keep_adjoint_buffer(std::vector<double>&& v) {
    if (v.capacity() > (size_t(64) << 20) / sizeof(double)) return;  // (a big image's is given back)
    std::lock_guard<std::mutex> lock(spare_mutex);
    if ((int)spare_buffers.size() < ThreadPool::hardware_threads()) spare_buffers.push_back(std::move(v));
}

// dL/d(premultiplied scene colour, background under it excluded) of each pixel, from
// dL/d(straight output) and the output itself. Parallel over rows: pixels are independent.
void pixel_adjoints(const RenderOptions& o, const float* image, const float* d_image, std::vector<double>& g) {
    const int W = o.width, H = o.height;
    g = adjoint_buffer(4 * (size_t)W * H);
    double bg[4];
    premultiplied_background(o, bg);
    constexpr int ROWS = 16;  // rows per task
    ThreadPool::instance().parallel_for((H + ROWS - 1) / ROWS, o.threads, [&](int task, int) {
        for (size_t p = (size_t)task * ROWS * W, end = std::min((size_t)(task + 1) * ROWS, (size_t)H) * W; p < end; ++p) {
            const float* s = image + 4 * p;
            const float* ds = d_image + 4 * p;
            double* gp = g.data() + 4 * p;
            if (o.premultiplied) {  // total = scene + (1 - scene.a) * background
                for (int i = 0; i < 4; ++i) gp[i] = ds[i];
                gp[3] -= ds[0] * bg[0] + ds[1] * bg[1] + ds[2] * bg[2] + ds[3] * bg[3];
                continue;
            }
            double a = s[3];
            if (a <= 0) {
                // An empty pixel: its straight colour jumps from 0 to the colour of whatever
                // comes to cover it (no derivative), but its alpha is the premultiplied alpha
                // (background empty too), so a boundary moving into it still has a gradient
                // through alpha. (Skipping such pixels gave a shape's edge lying exactly on a
                // pixel line no gradient towards the empty side: the boundary sample there
                // lands in the empty pixel.)
                gp[0] = gp[1] = gp[2] = 0;
                gp[3] = ds[3];
                continue;
            }
            double gc[4];
            double sum = 0;
            for (int i = 0; i < 3; ++i) {
                gc[i] = ds[i] / a;  // straight = premultiplied / alpha
                sum += ds[i] * s[i];
            }
            gc[3] = ds[3] - sum / a;
            // total = scene + (1 - scene.a) * background
            double gb = gc[0] * bg[0] + gc[1] * bg[1] + gc[2] * bg[2] + gc[3] * bg[3];
            for (int i = 0; i < 4; ++i) gp[i] = gc[i];
            gp[3] -= gb;
        }
    });
}

// Whether any pixel of [x0, x1) x [y0, y1) has a non-zero adjoint.
bool any_adjoint(const double* gpix, int W, int x0, int y0, int x1, int y1) {
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const double* gp = gpix + 4 * ((size_t)y * W + x);
            if (gp[0] != 0 || gp[1] != 0 || gp[2] != 0 || gp[3] != 0) return true;
        }
    return false;
}

// The boundary pieces of every draw, each with its number of samples (density per pixel
// of length). A segment's length is its control polygon's, which exceeds its arc length
// most where the speed along it varies most, i.e. where samples uniform in t are noisiest:
// counting by arc length instead lost 0.05-0.25 dB on the demo (3 seeds).
//
// A piece's count is capped at what its length inside the canvas can need (a cubic crosses
// the canvas at most a few times: 4 (W + H) pixels of length): a segment 1e9 pixels long
// would otherwise ask for billions of samples, nearly all off the canvas. The cap keeps the
// estimate unbiased (each sample is weighted by length / count), only noisier there.
//
// A piece none of whose samples can lie where boundary_sample uses one (within R of the
// canvas) gets no samples, certainly (its bounds below miss that area): a stroke 10^7 px
// wide drew a thousand samples on each offset curve and join of every item, millions of
// pixels away, and threw them out one by one. (Its count is 0, not the piece dropped: the
// other pieces' random numbers, keyed by their place in the list, stay the same.)
//
// Each piece's box (pixel space, the whole of what its samples can reach before the
// filter) goes to `boxes`, in the pieces' order, for allot_by_adjoint below.
std::vector<Piece> boundary_pieces(const SceneView& sc_, double density_, int width, int height, double R,
                                   int threads, std::vector<Box>& boxes) {
    const double cap = std::ceil(density_ * 4.0 * ((double)width + height));
    auto count = [&](double len) { return clamp_to_int(std::ceil(std::min(density_ * len, cap)), 1, 1 << 30); };
    // Where samples count, a little grown (for rounding), in pixel space.
    const Box canvas = grown(Box{-R, -R, width + R, height + R}, 1.0);
    auto reaches = [&](const Box& pixel_box) { return valid(pixel_box) && overlaps(pixel_box, canvas); };
    // A stroke-space box in pixel space (its corners through the metric's inverse).
    auto pixel_box = [&](const PreparedDraw& d, const Box& b) {
        if (d.metric_identity) return b;
        Box out;
        for (Vec2 c : {Vec2{b.x0, b.y0}, Vec2{b.x1, b.y0}, Vec2{b.x0, b.y1}, Vec2{b.x1, b.y1}}) expand(out, d.metric_inv * c);
        return out;
    };
    // Whether the segment a-b (stroke space) passes through that area (Liang-Barsky clipping
    // in pixel space).
    auto segment_reaches = [&](const PreparedDraw& d, Vec2 a, Vec2 b) {
        if (!d.metric_identity) {
            a = d.metric_inv * a;
            b = d.metric_inv * b;
        }
        double t0 = 0, t1 = 1;
        const double dx = b.x - a.x, dy = b.y - a.y;
        auto clip = [&](double p, double q) {  // p t <= q
            if (p == 0) return q >= 0;
            double r = q / p;
            if (p < 0) t0 = std::max(t0, r);
            else t1 = std::min(t1, r);
            return t0 <= t1;
        };
        return clip(-dx, a.x - canvas.x0) && clip(dx, canvas.x1 - a.x) && clip(-dy, a.y - canvas.y0) &&
               clip(dy, canvas.y1 - a.y);
    };
    // An offset curve of a stroke item (side +1 or -1) lies within (its curve's box) +
    // hw (its normals' box): the normals turn within the cone of the hodograph's control
    // vectors, where that cone is narrower than a right angle each way (else, any way).
    auto offset_reaches = [&](const PreparedDraw& d, const StrokeSegment& s, int side) {
        const Segment& c = s.seg;
        const double hw = d.varying ? s.hw_max : d.half_width;
        Box curve;
        for (int i = 0; i <= c.degree; ++i) expand(curve, c.p[i]);
        Box normals{-1, -1, 1, 1};
        Vec2 axis{0, 0};
        for (int i = 0; i < c.degree; ++i) {
            Vec2 h = c.p[i + 1] - c.p[i];
            double l = length(h);
            if (l > 0) axis = axis + (1 / l) * h;
        }
        double la = length(axis);
        if (la > 0) {
            axis = (1 / la) * axis;
            double cos_min = 1;
            for (int i = 0; i < c.degree; ++i) {
                Vec2 h = c.p[i + 1] - c.p[i];
                double l = length(h);
                if (l > 0) cos_min = std::min(cos_min, dot(h, axis) / l);
            }
            if (cos_min > 0.1) {  // every tangent within acos(cos_min) of the axis
                Vec2 n = side * perp(axis);
                double half = std::acos(std::min(1.0, cos_min)) + 1e-6, a = std::atan2(n.y, n.x);
                double lo = a - half, hi = a + half;
                Box arc;
                expand(arc, {std::cos(lo), std::sin(lo)});
                expand(arc, {std::cos(hi), std::sin(hi)});
                for (int q = -4; q <= 4; ++q)  // the axis directions within the arc
                    if (q * M_PI / 2 > lo && q * M_PI / 2 < hi) expand(arc, {std::cos(q * M_PI / 2), std::sin(q * M_PI / 2)});
                normals = arc;
            }
        }
        if (d.varying) {  // (the width runs from 0 up)
            expand(normals, {0, 0});
        }
        Box b{curve.x0 + hw * normals.x0, curve.y0 + hw * normals.y0, curve.x1 + hw * normals.x1,
              curve.y1 + hw * normals.y1};
        return reaches(pixel_box(d, grown(b, 1e-6 * (1 + hw))));
    };
    // The outline an end piece samples (see BoundarySampler::outline): a disk's circle,
    // a join polygon's outer edges, a square cap's three outer edges, a butt end's line.
    auto end_reaches = [&](const PreparedDraw& d, const StrokeSegment& s, int side) {
        const StrokeEnd& e = side == 0 ? s.start : s.end;
        const double hw = e.hw, pad = 1e-6 * (1 + hw);
        // (the outline is built again from the whole segments' frames: the same to rounding)
        auto edge = [&](Vec2 a, Vec2 b) {
            Vec2 u = b - a;
            double l = length(u);
            Vec2 g = l > 0 ? (pad / l) * u : Vec2{pad, 0};
            return segment_reaches(d, a - g - perp(g), b + g - perp(g)) ||
                   segment_reaches(d, a - g + perp(g), b + g + perp(g)) || segment_reaches(d, a, b);
        };
        if (e.kind == StrokeEnd::DISK) {
            double far = 0;  // the canvas inside the disk: the circle misses it
            for (Vec2 c : {Vec2{canvas.x0, canvas.y0}, Vec2{canvas.x1, canvas.y0}, Vec2{canvas.x0, canvas.y1},
                           Vec2{canvas.x1, canvas.y1}})
                far = std::max(far, distance(to_stroke_space(d, c), e.center));
            if (hw - pad > far) return false;
            return reaches(pixel_box(d, grown(Box{e.center.x, e.center.y, e.center.x, e.center.y}, hw + pad)));
        }
        if (e.kind == StrokeEnd::POLYGON) {
            for (int i = 1; i + 1 < e.n_poly; ++i)
                if (edge(e.poly[i], e.poly[i + 1])) return true;
            return false;
        }
        if (e.kind == StrokeEnd::SQUARE) {
            Vec2 u = perp(e.axis), a = e.center + hw * u, b = e.center + hw * e.axis + hw * u,
                 c = e.center + hw * e.axis - hw * u, f = e.center - hw * u;
            return edge(a, b) || edge(b, c) || edge(c, f);
        }
        Vec2 at = side == 0 ? s.seg.p[0] : seg_end(s.seg);  // a butt end: the end normal line
        Vec2 n = perp(seg_end_tangent(s.seg, side == 1));
        return edge(at - hw * n, at + hw * n);
    };
    // (A stroke's pieces take the draw's box, which holds its whole outline.)
    auto draw_pieces = [&](int di, std::vector<Piece>& out, std::vector<Box>& out_boxes) {
        const PreparedDraw& d = sc_.draws[di];
        if (!valid(d.box)) return;
        const size_t before = out.size();
        if (d.is_ellipse) {
            double r = std::max(d.ellipse.r0, d.ellipse.r1) + (d.kind == DRAW_STROKE ? d.half_width : 0);
            double len = 2 * M_PI * r * (d.kind == DRAW_STROKE ? d.metric_scale : 1.0);
            int n = reaches(d.box) ? count(len) : 0;
            if (d.kind == DRAW_FILL) out.push_back({Piece::ELLIPSE, di, 0, 0, n});
            else for (int s = -1; s <= 1; s += 2) out.push_back({Piece::ELLIPSE, di, 0, s, n});
            out_boxes.resize(out.size(), d.box);
            return;
        }
        for (int k = 0; k < d.n_items; ++k) {
            if (d.kind == DRAW_FILL) {
                const PreparedSegment& seg = sc_.fill_items[d.first_item + k];
                out.push_back({Piece::FILL_SEGMENT, di, k, 0, reaches(seg.box) ? count(polygon_length(seg.seg)) : 0});
                out_boxes.push_back(seg.box);
            } else {
                // Offset curves are about as long as the curve plus hw times its turning.
                const StrokeSegment& s = sc_.stroke_items[d.first_item + k];
                // (Per-point widths: the largest half width, plus how much the width varies.)
                Vec2 ta = seg_end_tangent(s.seg, false), tb = seg_end_tangent(s.seg, true);
                double turn = std::acos(std::clamp(dot(ta, tb), -1.0, 1.0));
                double hw = d.varying ? s.hw_max : d.half_width, vary = 0;
                if (d.varying)
                    for (int i = 0; i < s.seg.degree; ++i) vary += std::fabs(s.hw[i + 1] - s.hw[i]);
                double len = (polygon_length(s.seg) + hw * turn + vary) * d.metric_scale;
                for (int side = -1; side <= 1; side += 2)
                    out.push_back({Piece::OFFSET, di, k, side, offset_reaches(d, s, side) ? count(len) : 0});
                // Caps and joins only where there are some (pieces of one curve meet smoothly).
                auto end_len = [&](double h) { return (2 * M_PI * h + 4 * h * d.miter_limit) * d.metric_scale; };
                if (s.start.kind != StrokeEnd::NONE || s.butt_start)
                    out.push_back({Piece::END, di, k, 0, end_reaches(d, s, 0) ? count(end_len(s.start.hw)) : 0});
                if (s.end.kind != StrokeEnd::NONE || s.butt_end)
                    out.push_back({Piece::END, di, k, 1, end_reaches(d, s, 1) ? count(end_len(s.end.hw)) : 0});
            }
        }
        out_boxes.resize(before + (out.size() - before), d.box);
    };
    // Runs of draws on the threads, joined in draw order: the serial list exactly.
    const int n_draws = (int)sc_.draws.size();
    threads = draw_threads(threads, n_draws);
    const std::vector<int> bounds = draw_runs(sc_.draws.data(), n_draws, threads);
    const int n_runs = (int)bounds.size() - 1;
    std::vector<std::vector<Piece>> runs(n_runs);
    std::vector<std::vector<Box>> run_boxes(n_runs);
    ThreadPool::instance().parallel_for(n_runs, threads, [&](int r, int) {
        for (int di = bounds[r]; di < bounds[r + 1]; ++di) draw_pieces(di, runs[r], run_boxes[r]);
    });
    if (n_runs == 1) {
        boxes = std::move(run_boxes[0]);
        return std::move(runs[0]);
    }
    std::vector<Piece> out;
    size_t n = 0;
    for (const auto& run : runs) n += run.size();
    out.reserve(n);
    boxes.clear();
    boxes.reserve(n);
    for (int r = 0; r < n_runs; ++r) {
        out.insert(out.end(), runs[r].begin(), runs[r].end());
        boxes.insert(boxes.end(), run_boxes[r].begin(), run_boxes[r].end());
    }
    return out;
}

// A boundary budget (RenderOptions::boundary_budget, samples per pixel of the image): where
// the pieces ask for more samples than budget x W x H, the samples are allotted instead in
// proportion to each piece's asked count times the mean pixel adjoint (|dL/dcolour|,
// summed over the channels) of the tiles its box reaches, grown by the filter: the
// boundary term is an integral of the adjoint times the jump along the boundary, so
// where the adjoints are small its samples add little but noise. A dense trace's
// boundary is longer than its image is wide many times over, and most of it lies where
// the fit is already good.
//
// Unbiased: a piece that gets n >= 1 samples is still sampled in n strata, each weighted
// by its length / n; one that would get e < 1 is drawn by lot with chance e (keyed by the
// seed and the piece) and its sample then counts 1 / e (Piece::scale). Only pieces whose
// whole reach has zero adjoint get none for certain, and they would add exactly 0.
void allot_by_adjoint(std::vector<Piece>& pieces, const std::vector<Box>& boxes, const std::vector<double>& gpix,
                      int W, int H, double R, double budget, uint64_t seed) {
    if (budget <= 0) return;
    const double total_budget = budget * (double)W * H;
    double asked = 0;
    for (const Piece& pc : pieces) asked += pc.count;
    if (asked <= total_budget) return;
    // Summed-area table of the adjoint's magnitude per tile.
    const int nx = (W + TILE - 1) / TILE, ny = (H + TILE - 1) / TILE;
    std::vector<double> sat((size_t)(nx + 1) * (ny + 1), 0.0);
    for (int ty = 0; ty < ny; ++ty)
        for (int tx = 0; tx < nx; ++tx) {
            double m = 0;
            for (int y = ty * TILE, y1 = std::min(H, y + TILE); y < y1; ++y)
                for (int x = tx * TILE, x1 = std::min(W, x + TILE); x < x1; ++x) {
                    const double* gp = gpix.data() + 4 * ((size_t)y * W + x);
                    m += std::fabs(gp[0]) + std::fabs(gp[1]) + std::fabs(gp[2]) + std::fabs(gp[3]);
                }
            sat[(size_t)(ty + 1) * (nx + 1) + tx + 1] = m + sat[(size_t)ty * (nx + 1) + tx + 1] +
                                                       sat[(size_t)(ty + 1) * (nx + 1) + tx] -
                                                       sat[(size_t)ty * (nx + 1) + tx];
        }
    // Mean adjoint per pixel over the tiles a box reaches (grown by the filter and a pixel).
    auto importance = [&](const Box& b) {
        if (!valid(b)) return 0.0;
        const double g = R + 1;
        int x0 = clamp_to_int(std::floor((b.x0 - g) / TILE), 0, nx), x1 = clamp_to_int(std::floor((b.x1 + g) / TILE) + 1, 0, nx);
        int y0 = clamp_to_int(std::floor((b.y0 - g) / TILE), 0, ny), y1 = clamp_to_int(std::floor((b.y1 + g) / TILE) + 1, 0, ny);
        if (x1 <= x0 || y1 <= y0) return 0.0;
        double m = sat[(size_t)y1 * (nx + 1) + x1] - sat[(size_t)y0 * (nx + 1) + x1] - sat[(size_t)y1 * (nx + 1) + x0] +
                   sat[(size_t)y0 * (nx + 1) + x0];
        return std::max(0.0, m) / ((double)(x1 - x0) * (y1 - y0) * TILE * TILE);
    };
    std::vector<double> want(pieces.size());
    double sum = 0;
    for (size_t k = 0; k < pieces.size(); ++k) sum += (want[k] = pieces[k].count > 0 ? pieces[k].count * importance(boxes[k]) : 0);
    if (!(sum > 0)) return;  // (no adjoint anywhere: every sample would add 0; leave them)
    for (size_t k = 0; k < pieces.size(); ++k) {
        Piece& pc = pieces[k];
        if (pc.count == 0) continue;
        // (never more than asked: the budget moves samples away from where they add little)
        const double e = std::min((double)pc.count, total_budget * want[k] / sum);
        if (e >= 1) {
            pc.count = (int)std::ceil(e);
            continue;
        }
        double u, unused;
        sample_uniform2(seed ^ 0x5eedb0d9e7a11077ull, (uint64_t)k, 0, u, unused);
        pc.count = e > 0 && u < e ? 1 : 0;
        pc.scale = pc.count ? 1 / e : 1;
    }
}


}  // namespace

BackwardPlan plan_backward(const PreparedScene& prepared, const RenderOptions& o, const float* image,
                           const float* d_image, double boundary_density) {
    PhaseTimer timer(PHASE_PLAN);
    BackwardPlan plan;
    plan.options = settled(o);
    const double R = plan.options.filter_radius;
    // Boundary samples reach pixels within R of them, so tiles must see that far out.
    plan.bins = bin_draws(prepared, o.width, o.height, (o.mode == MODE_ANALYTIC ? 2 * R : R) + 4 * EPS_NORMAL, false,
                          o.threads);
    pixel_adjoints(o, image, d_image, plan.gpix);
    const SceneView sc = prepared.view();
    if (o.mode == MODE_MC) {
        std::vector<Box> boxes;
        plan.pieces = boundary_pieces(sc, boundary_density, o.width, o.height, R, o.threads, boxes);
        allot_by_adjoint(plan.pieces, boxes, plan.gpix, o.width, o.height, R, o.boundary_budget, o.seed);
    }
    BoundaryContext& bc = plan.boundary;
    bc.width = o.width;
    bc.height = o.height;
    bc.R = R;
    bc.filter = o.filter;
    bc.filter_integral = filter_integral(o.filter, R);
    bc.no_layers = sc.layer_parent.size() <= 1;
    bc.gpix = plan.gpix.data();
    // Hits at a point: at most the entries of its tile, and one forced draw. Tape: per
    // hit an OVER and up to the depth of layers opened; closing them all at the end.
    int most = 0;
    for (int t = 0; t + 1 < (int)plan.bins.start.size(); ++t) most = std::max(most, plan.bins.start[t + 1] - plan.bins.start[t]);
    int depth = 0;
    for (int32_t dl : prepared.layer_depth) depth = std::max(depth, (int)dl);
    plan.max_hits = most + 1;
    plan.max_ops = plan.max_hits * (1 + 2 * (depth + 1)) + depth + 1;
    return plan;
}

bool render_backward(const PreparedScene& prepared, const SceneArrays& a, const RenderOptions& o, const float* image,
                     const float* d_image, double boundary_density, SceneGrads& out, const ListSizes* fixed) {
    BackwardPlan plan = plan_backward(prepared, o, image, d_image, boundary_density);
    const SceneView sc = prepared.view();
    const TileView bins = plan.bins.view();
    const int W = o.width, H = o.height;
    int lanes = std::max(1, o.threads > 0 ? o.threads : ThreadPool::hardware_threads());
    std::vector<SceneGrads> grads(lanes);
    for (SceneGrads& g : grads) g.resize_like(a);
    const int n_tiles = bins.nx * bins.ny;
    const ListSizes sizes = fixed ? *fixed : ListSizes{plan.max_hits, plan.max_ops};
    std::vector<char> overflowed(lanes, 0);

    // Per lane: its own gradients and lists (sized so that no sample can overflow them,
    // unless fixed sizes were asked for).
    struct LaneLists {
        std::vector<Hit> hits;
        std::vector<TapeOp> ops;
        std::vector<Quad> g_hits;
        explicit LaneLists(ListSizes n) : hits(n.hits), ops(n.ops), g_hits(n.hits) {}
        SampleScratch scratch() {
            return {{hits.data(), (int)hits.size()}, {{ops.data(), (int)ops.size()}}, {g_hits.data(), (int)g_hits.size()}};
        }
    };
    const bool fields = o.mode == MODE_ANALYTIC && !o.brute_force;
    std::optional<PhaseTimer> timer(PHASE_BACKWARD_INTERIOR);
    const std::vector<StrokeBound> stroke_bound = fields ? stroke_bounds(sc, bins, lanes) : std::vector<StrokeBound>();
    ThreadPool::instance().parallel_for(lanes, lanes, [&](int lane, int) {
        const GradView g = grads[lane].view();
        LaneLists lists(sizes);
        SampleScratch w = lists.scratch();
        SampleGrid grid;
        TileFields tile_fields;
        for (int tile = lane; tile < n_tiles; tile += lanes) {
            int tx = tile % bins.nx, ty = tile / bins.nx;
            const int x0 = tx * TILE, x1 = std::min(W, x0 + TILE), y0 = ty * TILE, y1 = std::min(H, y0 + TILE);
            // The analytical mode: the tile's long fill entries ahead, segment by segment
            // (scene/field.h), where some pixel of the tile has a gradient.
            FieldView view;
            if (fields && bins.count(tile) > 0 && !cancelled() && any_adjoint(plan.gpix.data(), W, x0, y0, x1, y1)) {
                grid.build(bins, tile, W, H, plan.options.samples, plan.options.filter_radius);
                tile_fields.compute(sc, bins, tile, grid, plan.options.filter_radius, true,
                                    stroke_bound.empty() ? nullptr : stroke_bound.data());
                view = tile_fields.view();
            }
            for (int y = y0; y < y1 && !cancelled(); ++y)
                for (int x = x0; x < x1; ++x)
                    pixel_backward(sc, bins, plan.options, plan.gpix.data() + 4 * ((size_t)y * W + x), x, y, w, g,
                                   view.slot ? &view : nullptr);
        }
        if (w.overflow()) overflowed[lane] = 1;  // (the flags stay set once raised)
    });

    timer.emplace(PHASE_BACKWARD_BOUNDARY);
    if (!plan.pieces.empty()) {
        BoundarySampler pass{sc, o.seed};
        ThreadPool::instance().parallel_for(lanes, lanes, [&](int lane, int) {
            const GradView g = grads[lane].view();
            std::vector<Hit> hit_list(sizes.hits);  // (the boundary term needs no tape)
            Buffer<Hit> hits{hit_list.data(), (int)hit_list.size()};
            for (size_t k = lane; k < plan.pieces.size() && !cancelled(); k += lanes) {
                const Piece& pc = plan.pieces[k];
                for (int j = 0; j < pc.count; ++j) boundary_sample(sc, bins, pass, pc, j, (uint64_t)k, plan.boundary, hits, g);
            }
            if (hits.overflow) overflowed[lane] = 1;
        });
    }

    timer.reset();
    keep_adjoint_buffer(std::move(plan.gpix));
    for (char f : overflowed)
        if (f) return false;
    out = grads[0];
    for (int l = 1; l < lanes; ++l) out.add(grads[l]);
    return true;
}

}  // namespace vf
