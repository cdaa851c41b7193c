// Builds the PreparedScene from the flat arrays: control points per segment, bounds,
// y-monotone pieces for ray crossings, stroke pieces (joins and caps), paints (from the
// paints table), layers.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/float_bounds.h"
#include "scene/layers.h"
#include "scene/scene.h"
#include "scene/stroke.h"

namespace vf {
namespace {

void check(bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("vecfit core: " + what);
}

bool finite(double v) { return std::isfinite(v); }

}  // namespace


PreparedSegment prepare_segment(const Segment& s, const int32_t* idx) {
    PreparedSegment ps;
    ps.seg = s;
    for (int i = 0; i < 4; ++i) ps.point_index[i] = idx ? idx[i] : -1;
    double tx[2], ty[2];
    int nx = seg_extrema(s, 0, tx), ny = seg_extrema(s, 1, ty);
    ps.box = seg_bbox(s, 0, 1, tx, nx, ty, ny);
    ps.n_split = 0;
    ps.split[ps.n_split++] = 0;
    for (int i = 0; i < ny; ++i)
        if (ty[i] > ps.split[ps.n_split - 1]) ps.split[ps.n_split++] = ty[i];
    ps.split[ps.n_split++] = 1;
    for (int i = 0; i < ps.n_split; ++i) ps.split_y[i] = seg_eval(s, ps.split[i]).y;
    double ax[4], ay[4];
    ps.power_basis(ax, ay);
    for (int k = 0; k + 1 < ps.n_split; ++k) {
        Box b = seg_bbox(s, ps.split[k], ps.split[k + 1], tx, nx, nullptr, 0);  // (no y-extrema inside)
        ps.piece_x0[k] = float_below(b.x0);
        ps.piece_x1[k] = float_above(b.x1);
        ps.n_sub = s.degree == 1 ? 1 : PreparedSegment::SUB;
        for (int j = 1; j < ps.n_sub; ++j) {
            double t = ps.sub_t(k, j);
            // the ends are the piece's own values, the cuts those monotone_crossing_within sees
            ps.sub_cut[k][j - 1] = ((ay[3] * t + ay[2]) * t + ay[1]) * t + ay[0];
        }
        // x ranges from the power basis (cheaper than de Casteljau; this runs on every
        // call), widened as seg_bbox widens boxes so that rounding cannot shrink them.
        auto X = [&](double t) { return ((ax[3] * t + ax[2]) * t + ax[1]) * t + ax[0]; };
        double grow = 1e-9 * (1 + vmax(vmax(std::fabs(ps.box.x0), std::fabs(ps.box.x1)),
                                       vmax(std::fabs(ps.box.y0), std::fabs(ps.box.y1))));
        double x_next = X(ps.sub_t(k, 0));
        for (int j = 0; j < ps.n_sub; ++j) {
            double t0 = ps.sub_t(k, j), t1 = ps.sub_t(k, j + 1), x_first = x_next;
            x_next = X(t1);
            double lo = vmin(x_first, x_next), hi = vmax(x_first, x_next);
            for (int i = 0; i < nx; ++i)
                if (tx[i] > t0 && tx[i] < t1) {
                    double x = X(tx[i]);
                    lo = vmin(lo, x);
                    hi = vmax(hi, x);
                }
            ps.sub_x0[k][j] = float_below(lo - grow);
            ps.sub_x1[k][j] = float_above(hi + grow);
        }
    }
    return ps;
}

namespace {

bool is_point(const Segment& s) {
    for (int i = 1; i <= s.degree; ++i)
        if (dot(s.p[i] - s.p[0], s.p[i] - s.p[0]) > 1e-24) return false;
    return true;
}

// Pixel-space bounds of a stroke-space box.
Box to_pixel_box(const Box& b, const Mat2& inv) {
    Box out;
    expand(out, inv * Vec2{b.x0, b.y0});
    expand(out, inv * Vec2{b.x1, b.y0});
    expand(out, inv * Vec2{b.x0, b.y1});
    expand(out, inv * Vec2{b.x1, b.y1});
    return out;
}

void add_end_to_box(Box& b, const StrokeEnd& e, double hw) {
    switch (e.kind) {
        case StrokeEnd::DISK:
            expand(b, e.center + Vec2{-hw, -hw});
            expand(b, e.center + Vec2{hw, hw});
            break;
        case StrokeEnd::SQUARE:  // the half square lies within hw * sqrt(2) of the end point
            expand(b, e.center + Vec2{-hw * 1.5, -hw * 1.5});
            expand(b, e.center + Vec2{hw * 1.5, hw * 1.5});
            break;
        case StrokeEnd::POLYGON:
            for (int i = 0; i < e.n_poly; ++i) expand(b, e.poly[i]);
            break;
        default: break;
    }
}

// Whether the squared distance from any point within `reach` of the segment is strictly
// convex along it, so that it has at most one critical point there. True when the
// radius of curvature everywhere exceeds the segment's length plus the reach: the speed
// is at least the smallest projection of the hodograph's control points on the chord
// direction u, and |B''| at most the largest second difference, so R >= speed^2 / |B''|.
bool is_simple(const Segment& s, Vec2 u, double reach) {
    if (s.degree == 1) return true;
    double min_proj = 1e300, max_second = 0, len = 0;
    for (int i = 0; i < s.degree; ++i) {
        min_proj = std::min(min_proj, s.degree * dot(s.p[i + 1] - s.p[i], u));
        len += distance(s.p[i], s.p[i + 1]);
    }
    for (int i = 0; i + 2 <= s.degree; ++i)
        max_second = std::max(max_second, s.degree * (s.degree - 1) * length(s.p[i] - 2.0 * s.p[i + 1] + s.p[i + 2]));
    if (min_proj <= 0) return false;
    if (max_second <= 0) return true;
    return min_proj * min_proj / max_second > len + reach;
}

// Segment g as draw d strokes it (stroke space; nearly straight curves straightened), or
// false where it has no length (no sweep, no direction).
bool stroke_source(const PreparedScene& sc, int g, const PreparedDraw& d, Segment& s) {
    s = sc.segments[g].seg;
    if (!d.metric_identity) s = transformed(s, d.metric);
    if (is_point(s)) return false;
    s = straightened(s, d.varying);
    return true;
}

// How many stroke items a stroked segment becomes: curves are split into pieces of about
// 8 units (exactly, by de Casteljau): their chord-frame bounds get tight, so far fewer
// samples need the quintic. Measured on 256 random strokes: forward 4x (256 px) to 7x
// (512 px) faster.
int stroke_pieces(const Segment& s) {
    double len = 0;
    for (int i = 0; i < s.degree; ++i) len += distance(s.p[i], s.p[i + 1]);
    return s.degree == 1 ? 1 : clamp_to_int(std::ceil(len / 8.0), 1, 16);
}

// The number of stroke items build_stroke_subpath appends for the subpath.
size_t stroke_subpath_items(const PreparedScene& sc, int first, int count, const PreparedDraw& d) {
    size_t n = 0;
    Segment s;
    for (int g = first; g < first + count; ++g)
        if (stroke_source(sc, g, d, s)) n += stroke_pieces(s);
    return n == 0 && d.cap != CAP_BUTT && count > 0 ? 1 : n;
}

// Stroke pieces of one subpath of a stroke draw, appended to out (built in place: a long
// path's items are hundreds of megabytes, and building them in a vector of their own and
// copying them over, each growing by doubling, spent most of the preparation in page
// faults; the caller reserves room, stroke_subpath_items).
void build_stroke_subpath(const PreparedScene& sc, int first, int count, bool closed,
                          const PreparedDraw& d, std::vector<StrokeSegment>& out) {
    const bool var = d.varying;
    double hw = d.half_width;
    // Half width of point index k (per-point widths), or the draw's.
    auto point_hw = [&](int32_t k) { return var && k >= 0 ? std::max(0.0, sc.point_hw[k]) : hw; };
    const size_t base = out.size();
    for (int g = first; g < first + count; ++g) {
        Segment s;
        if (!stroke_source(sc, g, d, s)) continue;
        // The width profile as a 1-D Bézier (x coordinates) split along with the curve.
        Segment w;
        w.degree = s.degree;
        const int32_t* idx = sc.segments[g].point_index;  // straightened(s, true) keeps the degree
        for (int i = 0; i <= s.degree; ++i) w.p[i] = {point_hw(var ? idx[i] : -1), 0};
        const int pieces = stroke_pieces(s);
        for (int k = 0; k < pieces; ++k) {
            out.emplace_back();
            StrokeSegment& ss = out.back();
            ss.t0 = (double)k / pieces;
            ss.t1 = (double)(k + 1) / pieces;
            ss.seg = pieces == 1 ? s : seg_part(s, ss.t0, ss.t1);
            Segment wp = pieces == 1 || !var ? w : seg_part(w, ss.t0, ss.t1);
            ss.hw_max = 0;
            for (int i = 0; i <= s.degree; ++i) {
                ss.hw[i] = wp.p[i].x;
                ss.hw_max = std::max(ss.hw_max, ss.hw[i]);
            }
            ss.source = g;
        }
    }
    StrokeSegment* segs = out.data() + base;  // (this subpath's; room was reserved)
    // Vertex widths at an item's start and end: the width of the point there.
    auto start_index = [&](const StrokeSegment& ss) { return sc.segments[ss.source].point_index[0]; };
    auto end_index = [&](const StrokeSegment& ss) {
        const SegmentSource& src = sc.segments[ss.source];
        return src.point_index[src.seg.degree];
    };
    auto set_width = [&](StrokeEnd& e, int32_t k) {
        e.hw = point_hw(k);
        e.width_index = var ? k : -1;
    };
    const int n_segs = (int)(out.size() - base);
    if (n_segs == 0) {
        // A zero-length subpath: a dot with round caps, a square with square caps (aligned
        // with the stroke space's x axis, i.e. the user space), nothing with butt caps.
        if (d.cap == CAP_BUTT || count == 0) return;
        Segment s = sc.segments[first].seg;
        if (!d.metric_identity) s = transformed(s, d.metric);
        StrokeSegment ss;
        ss.seg = s;
        ss.seg.degree = 1;
        ss.seg.p[1] = ss.seg.p[0];
        ss.source = first;
        int32_t k = sc.segments[first].point_index[0];
        double h = point_hw(k);
        ss.hw[0] = ss.hw[1] = ss.hw_max = h;
        ss.start = make_cap(s.p[0], {-1, 0}, d.cap, h);
        ss.end = make_cap(s.p[0], {1, 0}, d.cap, h);
        set_width(ss.start, k);
        set_width(ss.end, k);
        out.push_back(ss);
        segs = out.data() + base;
    } else {
        int n = n_segs;
        for (int i = 0; i < n; ++i) {
            bool last = i + 1 == n;
            if (last && !closed) {
                Vec2 t = seg_end_tangent(segs[i].seg, true);
                segs[i].end = make_cap(seg_end(segs[i].seg), t, d.cap, point_hw(end_index(segs[i])));
                set_width(segs[i].end, end_index(segs[i]));
                segs[i].butt_end = d.cap == CAP_BUTT;
            } else {
                StrokeSegment& next = segs[last ? 0 : i + 1];
                segs[i].next = (int)base + (last ? 0 : i + 1);
                next.prev = (int)base + i;
                if (var && !last && next.source == segs[i].source) {
                    // Pieces of one curve meet smoothly: no join (a disk of the local width
                    // could stick out of a sweep whose width changes fast).
                    segs[i].end.hw = segs[i].hw[segs[i].seg.degree];
                    continue;
                }
                // The vertex's width; where a zero-length segment was dropped between the
                // two, the points on either side may differ: the join takes the larger.
                int32_t k = end_index(segs[i]), k2 = start_index(next);
                if (var && point_hw(k2) > point_hw(k)) k = k2;
                segs[i].end = make_join(seg_end(segs[i].seg), seg_end_tangent(segs[i].seg, true),
                                        seg_end_tangent(next.seg, false), d.join, point_hw(k), d.miter_limit);
                next.bevel_start = segs[i].end.kind == StrokeEnd::POLYGON && segs[i].end.n_poly == 3;
                set_width(segs[i].end, k);
            }
        }
        if (!closed) {
            Vec2 t = seg_end_tangent(segs[0].seg, false);
            segs[0].start = make_cap(segs[0].seg.p[0], -t, d.cap, point_hw(start_index(segs[0])));
            set_width(segs[0].start, start_index(segs[0]));
            segs[0].butt_start = d.cap == CAP_BUTT;
        }
    }
    for (size_t i = base; i < out.size(); ++i) {
        StrokeSegment& ss = out[i];
        const Segment& s = ss.seg;
        Vec2 u = normalized(seg_end(s) - s.p[0]);
        if (u.x == 0 && u.y == 0) u = {1, 0};
        ss.frame_u = u;
        ss.s_min = ss.n_min = 1e300;
        ss.s_max = ss.n_max = -1e300;
        for (int i = 0; i <= s.degree; ++i) {
            Vec2 r = s.p[i] - s.p[0];
            ss.s_min = std::min(ss.s_min, dot(r, u));
            ss.s_max = std::max(ss.s_max, dot(r, u));
            ss.n_min = std::min(ss.n_min, cross(u, r));
            ss.n_max = std::max(ss.n_max, cross(u, r));
        }
        double reach = ss.hw_max;
        ss.simple = is_simple(s, u, reach + 4.0);  // reach: the half width plus any prefilter radius used
        Box b = grown(seg_bbox(ss.seg), reach);
        add_end_to_box(b, ss.start, ss.start.hw);
        add_end_to_box(b, ss.end, ss.end.hw);
        ss.box = d.metric_identity ? b : to_pixel_box(b, d.metric_inv);
    }
}

}  // namespace

PreparedScene prepare_scene(const SceneArrays& a) {
    PreparedScene sc;
    check(a.n_points >= 0 && a.n_segments >= 0 && a.n_draws >= 0, "negative array size");
    check(a.n_point_widths == 0 || a.n_point_widths == a.n_points, "point_widths must match points");
    sc.point_hw.resize(a.n_point_widths);
    for (int i = 0; i < a.n_point_widths; ++i) {
        if (!finite(a.point_widths[i])) check(false, "non-finite point width " + std::to_string(i));
        sc.point_hw[i] = 0.5 * a.point_widths[i];  // unclamped: a negative one gets no gradient
    }
    std::vector<Vec2> pts(a.n_points);
    for (int i = 0; i < a.n_points; ++i) {
        pts[i] = {a.points[2 * i], a.points[2 * i + 1]};
        // (the message only when it fails: a string per point was a third of this function)
        if (!(finite(pts[i].x) && finite(pts[i].y))) check(false, "non-finite point " + std::to_string(i));
    }

    // The segments checked and read once (control points in doubles); kept as sources only
    // where some draw strokes a path (fills prepare their own, below).
    std::vector<SegmentSource> sources(a.n_segments);
    for (int g = 0; g < a.n_segments; ++g) {
        const int32_t* row = a.segments + SEGMENT_COLS * g;
        SegmentSource& src = sources[g];
        src.seg.degree = row[0];
        check(src.seg.degree >= 1 && src.seg.degree <= 3, "segment degree must be 1, 2 or 3");
        for (int i = 0; i <= src.seg.degree; ++i) {
            int32_t k = row[1 + i];
            check(k >= 0 && k < a.n_points, "segment point index out of range");
            src.seg.p[i] = pts[k];
        }
        for (int i = 0; i < 4; ++i) src.point_index[i] = row[1 + i];
    }
    std::vector<Vec2>().swap(pts);
    bool strokes = false;
    for (int di = 0; di < a.n_draws; ++di) {
        const int32_t* row = a.draws + DRAW_COLS * di;
        strokes |= row[1] == DRAW_STROKE && row[0] >= 0 && row[0] < a.n_shapes &&
                   a.shapes[SHAPE_COLS * row[0]] == SHAPE_PATH;
    }

    sc.stop_offsets.assign(a.stop_offsets, a.stop_offsets + a.n_stops);
    sc.stop_colors.assign(a.stop_colors, a.stop_colors + 4 * a.n_stops);
    for (int q = 0; q < a.n_paints; ++q) {
        const int32_t* row = a.paints + PAINT_COLS * q;
        const float* f = a.paint_params + PAINT_FCOLS * q;
        PreparedPaint p;  // a row of the paints table
        p.kind = row[0];
        p.first_stop = row[1];
        p.n_stops = row[2];
        check(p.kind >= PAINT_SOLID && p.kind <= PAINT_RADIAL, "unknown paint kind");
        check(p.kind == PAINT_SOLID || (p.first_stop >= 0 && p.n_stops >= 1 &&
                                        p.first_stop + p.n_stops <= a.n_stops),
              "gradient stops out of range");
        p.to_paint = {f[0], f[1], f[2], f[3], f[4], f[5]};
        for (int i = 0; i < 4; ++i) p.rgba[i] = f[6 + i];
        for (int i = 0; i < 5; ++i) p.g[i] = f[6 + i];
        sc.paints.push_back(p);
    }

    check(a.n_layers >= 1, "at least the root layer is needed");
    sc.layer_parent.assign(a.layer_parents, a.layer_parents + a.n_layers);
    sc.layer_opacity.assign(a.layer_opacity, a.layer_opacity + a.n_layers);
    sc.layer_depth.assign(a.n_layers, 0);
    check(sc.layer_parent[0] == -1, "layer 0 must be the root");
    for (int l = 1; l < a.n_layers; ++l) {
        check(sc.layer_parent[l] >= 0 && sc.layer_parent[l] < l, "a layer's parent must come before it");
        sc.layer_depth[l] = sc.layer_depth[sc.layer_parent[l]] + 1;
        check(sc.layer_depth[l] < MAX_LAYER_DEPTH, "groups with opacity nested too deeply");
    }

    if (strokes) sc.segments = std::move(sources);  // (the stroke items refer to them)
    const std::vector<SegmentSource>& segs = strokes ? sc.segments : sources;
    // (every fill draw's segments and closing lines: counted first, so that the vector is
    // allocated once at its size)
    size_t n_fill = 0;
    for (int di = 0; di < a.n_draws; ++di) {
        const int32_t* row = a.draws + DRAW_COLS * di;
        if (row[1] != DRAW_FILL || row[0] < 0 || row[0] >= a.n_shapes) continue;
        const int32_t* shape = a.shapes + SHAPE_COLS * row[0];
        if (shape[0] != SHAPE_PATH || shape[1] < 0 || shape[2] < 0 || shape[1] + shape[2] > a.n_subpaths) continue;
        for (int b = shape[1]; b < shape[1] + shape[2]; ++b) {
            const int32_t* sp = a.subpaths + SUBPATH_COLS * b;
            if (sp[0] >= 0 && sp[1] >= 0 && sp[1] <= a.n_segments - sp[0]) n_fill += (size_t)sp[1] + 1;
        }
    }
    sc.fill_items.reserve(n_fill);
    for (int di = 0; di < a.n_draws; ++di) {
        const int32_t* row = a.draws + DRAW_COLS * di;
        const float* f = a.draw_params + DRAW_FCOLS * di;
        PreparedDraw d;
        d.shape = row[0];
        d.kind = row[1];
        d.fill_rule = row[2];
        d.paint = row[3];
        d.layer = row[4];
        d.cap = row[5];
        d.join = row[6];
        d.varying = row[7] != 0;
        check(d.shape >= 0 && d.shape < a.n_shapes, "draw shape out of range");
        check(d.paint >= 0 && d.paint < a.n_paints, "draw paint out of range");
        check(d.layer >= 0 && d.layer < a.n_layers, "draw layer out of range");
        d.half_width = 0.5 * std::max(0.0f, f[0]);
        d.miter_limit = std::max(1.0f, f[1]);
        d.metric = {f[2], f[3], f[4], f[5]};
        d.metric_identity = f[2] == 1 && f[3] == 0 && f[4] == 0 && f[5] == 1;
        d.metric_inv = inverse(d.metric);
        d.metric_scale = std::sqrt(std::fabs(det(d.metric_inv)));
        check(std::isfinite(d.metric_scale) && det(d.metric) != 0, "singular stroke metric");

        const int32_t* shape = a.shapes + SHAPE_COLS * d.shape;
        if (shape[0] == SHAPE_ELLIPSE) {
            check(shape[3] >= 0 && shape[3] < a.n_ellipses, "ellipse index out of range");
            check(!d.varying, "per-point widths need a stroked path");
            const float* e = a.ellipses + ELLIPSE_COLS * shape[3];
            Vec2 c{e[0], e[1]};
            Mat2 A{e[2], e[3], e[4], e[5]};
            d.is_ellipse = true;
            d.ellipse_row = shape[3];
            d.ellipse_center = c;
            d.ellipse_axes = A;
            if (d.kind == DRAW_STROKE && !d.metric_identity) {
                c = d.metric * c;
                A = {d.metric.a * A.a + d.metric.b * A.c, d.metric.a * A.b + d.metric.b * A.d,
                     d.metric.c * A.a + d.metric.d * A.c, d.metric.c * A.b + d.metric.d * A.d};
            }
            d.ellipse = ellipse_frame(c, A);
            double m = std::max(d.ellipse.r0, d.ellipse.r1) + (d.kind == DRAW_STROKE ? d.half_width : 0);
            Box b{c.x - m, c.y - m, c.x + m, c.y + m};
            d.box = d.kind == DRAW_STROKE && !d.metric_identity ? to_pixel_box(b, d.metric_inv) : b;
            // Axes all 0 (a circle of radius <= 0 kept in a fitting loop's pack, see
            // vecfit/renderer/persistent.py, or a scale of 0): nothing is drawn, as SVG
            // draws nothing (a point would have had the analytical kernel's half coverage).
            if (e[2] == 0 && e[3] == 0 && e[4] == 0 && e[5] == 0) d.box = Box{};
        } else {
            check(shape[0] == SHAPE_PATH, "unknown shape kind");
            check(!d.varying || (d.kind == DRAW_STROKE && a.n_point_widths == a.n_points),
                  "per-point widths need a stroked path and point_widths");
            check(shape[1] >= 0 && shape[2] >= 0 && shape[1] + shape[2] <= a.n_subpaths,
                  "shape subpaths out of range");
            d.first_item = d.kind == DRAW_FILL ? (int)sc.fill_items.size() : (int)sc.stroke_items.size();
            if (d.kind == DRAW_STROKE) {  // room for the draw's items (growing by doubling, for many draws)
                size_t n = sc.stroke_items.size();
                for (int b = shape[1]; b < shape[1] + shape[2]; ++b) {
                    const int32_t* sp = a.subpaths + SUBPATH_COLS * b;
                    check(sp[0] >= 0 && sp[1] >= 0 && sp[0] + sp[1] <= a.n_segments, "subpath segments out of range");
                    n += stroke_subpath_items(sc, sp[0], sp[1], d);
                }
                if (n > sc.stroke_items.capacity())
                    sc.stroke_items.reserve(std::max(n, 2 * sc.stroke_items.capacity()));
            }
            for (int b = shape[1]; b < shape[1] + shape[2]; ++b) {
                const int32_t* sp = a.subpaths + SUBPATH_COLS * b;
                int first = sp[0], count = sp[1];
                bool closed = sp[2] != 0;
                check(first >= 0 && count >= 0 && first + count <= a.n_segments, "subpath segments out of range");
                if (count == 0) continue;
                if (d.kind == DRAW_FILL) {
                    for (int g = first; g < first + count; ++g)
                        sc.fill_items.push_back(prepare_segment(segs[g].seg, segs[g].point_index));
                    if (!closed) {  // filling closes an open subpath with a straight line
                        const SegmentSource& last = segs[first + count - 1];
                        const SegmentSource& head = segs[first];
                        Segment line;
                        line.degree = 1;
                        line.p[0] = seg_end(last.seg);
                        line.p[1] = head.seg.p[0];
                        int32_t idx[4] = {last.point_index[last.seg.degree], head.point_index[0], -1, -1};
                        sc.fill_items.push_back(prepare_segment(line, idx));
                    }
                } else {
                    build_stroke_subpath(sc, first, count, closed, d, sc.stroke_items);
                }
            }
            d.n_items = (d.kind == DRAW_FILL ? (int)sc.fill_items.size() : (int)sc.stroke_items.size()) - d.first_item;
            if (d.varying) {  // the draw's half width: the largest (zero: draws nothing)
                d.half_width = 0;
                for (int i = 0; i < d.n_items; ++i) {
                    const StrokeSegment& ss = sc.stroke_items[d.first_item + i];
                    d.half_width = std::max({d.half_width, ss.hw_max, ss.start.hw, ss.end.hw});
                }
            }
            for (int i = 0; i < d.n_items; ++i) {
                const Box& b = d.kind == DRAW_FILL ? sc.fill_items[d.first_item + i].box
                                                   : sc.stroke_items[d.first_item + i].box;
                expand(d.box, {b.x0, b.y0});
                expand(d.box, {b.x1, b.y1});
            }
        }
        if (d.kind == DRAW_STROKE && d.half_width <= 0) d.box = Box{};  // draws nothing
        sc.draws.push_back(d);
    }
    return sc;
}

}  // namespace vf
