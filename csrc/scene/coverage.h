// Point queries against prepared draws: is a point covered (Monte Carlo), and its signed
// distance to the covered region (analytical prefilter; negative inside).
//
// Strokes follow the SVG model as a union of simple pieces, each in stroke space (pixel
// space mapped by the draw's metric, so that a stroke under a non-uniform transform is
// exact):
//   * per segment, the sweep of its normals of length w: p is inside when some critical
//     point t* of |B(t) - p| on [0, 1] (a root of the quintic for cubics) lies within w/2;
//   * per interior vertex, the join: a disk (round), the triangle between the two offset
//     end points (bevel), or that quadrilateral reaching to the miter tip (miter, falling
//     back to bevel past the miter limit);
//   * per free end, the cap: nothing (butt: the sweep ends at its end normal), a disk
//     (round) or the half square of depth w/2 beyond the end (square).
// Pieces meet along internal seams (a sweep's end normal, a join polygon's sides from the
// vertex, a cap's back edge). Signed distances treat seams as open: a point inside a piece
// is as deep as its distance to the piece's real boundary, so the analytical prefilter
// sees no lines inside a stroke; where two pieces disagree on a seam (a sweep and a bevel
// triangle) the image would jump there, which the seam rule prevents (bevel_edge).
// Why this form: each piece has a simple inside test and a signed distance, and the
// union's boundary is a set of curves with known normals (offset curves, disk arcs,
// polygon edges, butt end lines), which is what boundary sampling needs for gradients.
// A boundary point of one piece that lies inside another is not on the union's boundary;
// the gradient pass finds that out by evaluating the stroke with and without the piece.
//
// Per-point widths (a path with a width per control point, as diffvg's `thickness`):
// along a segment the half width is a Bézier of the segment's degree over the same
// parameter, hw(t) = sum hw_i b_i(t) (the widths are a third coordinate of the control
// polygon, so de Casteljau splits them with the curve). The sweep becomes the union of
// normal segments of half length hw(t): p is inside when at some critical point t* of
// |B(t) - p|, |B(t*) - p| <= hw(t*), and its signed distance is |B(t*) - p| - hw(t*)
// (diffvg's approach). Its boundary is the pair of offset curves B(t) +- hw(t) N(t),
// whose normals tilt by hw' (the Monte Carlo boundary term samples them as they are).
// Approximation, stated: a variable-width stroke is usually defined as the union of the
// disks of radius hw(t) centred on the curve, whose boundary (the envelope of those
// circles) touches each circle where its normal is tilted by asin(hw' / |B'|); the normal
// sweep reaches exactly hw(t) along the normal instead. The two agree to first order
// where |hw'| is small against |B'| (the envelope lies outside the sweep by about
// hw (1/cos - 1) of that angle: 0.5% of hw at a slope of 0.1) and differ where the width
// changes fast. The signed distance is then a pseudo-distance: exact along the normal,
// too large by sqrt(1 + (hw' / |B'|)^2) across a slanted edge (the prefilter's edge is
// that much sharper there; it still integrates to the same area to first order).
// Why this form: the inside test and the distance need only the critical points the
// uniform stroke already finds, the pieces stay a union of simple sets with known
// boundaries, and with equal widths it is the uniform stroke exactly. Caps and joins sit
// at vertices, where every segment meeting there has that point's width: they are built
// with the vertex's half width (StrokeEnd::hw) instead of the draw's.
#pragma once

#include "common/bezier.h"
#include "common/ellipse.h"
#include "scene/scene.h"

namespace vf {

// Which piece a signed distance came from, for its gradient (analytical prefilter).
// (Packed to 40 bytes: a Hit, which holds one, stays within two cache lines.)
struct SdfArg {
    enum Kind : int8_t { NONE, SEGMENT, ELLIPSE, SWEEP, BUTT, END, SEAM } kind = NONE;
    int8_t side = 0;   // BUTT / END / SEAM: 0 at the item's start, 1 at its end (SEAM: the
                       // bevel edge bounding the sweep, see bevel_edge); SEGMENT on the
                       // edge (see ON_EDGE): +1 / -1 where the inside lies along +/- the
                       // segment's left normal, 0 where it lies on both sides or neither
    // SEGMENT on the edge: a second segment also within ON_EDGE (the sample on a vertex,
    // e.g. a rect's corner on a pixel centre), its inside side, index (-1: none) and
    // parameter (a float: only its Bernstein weights use it)
    int8_t side2 = 0;
    int item = -1;     // fill or stroke item (global index)
    int item2 = -1;
    float t2 = 0;
    double t = 0;      // SEGMENT / SWEEP: parameter of the closest point
    Vec2 closest;      // SEGMENT / SWEEP / ELLIPSE: the closest point
};
static_assert(sizeof(SdfArg) == 40, "SdfArg grew: a Hit would span a third cache line");

// Signed crossings of the ray from p towards +x, up to and including x_max, with the
// segment; each y-monotone piece counts on the half-open range [y_low, y_high) so that
// pieces meeting at a vertex are counted once. +1 where the curve moves towards +y.
VF_HD int ray_crossings(const PreparedSegment& s, Vec2 p, double x_max = 1e300) {
    if (p.y < s.box.y0 || p.y > s.box.y1 || s.box.x1 <= p.x || s.box.x0 > x_max) return 0;
    int w = 0;
    for (int k = 0; k + 1 < s.n_split; ++k) {
        double ya = s.split_y[k], yb = s.split_y[k + 1];
        int dir;
        if (ya <= p.y && p.y < yb) dir = 1;
        else if (yb <= p.y && p.y < ya) dir = -1;
        else continue;
        if (s.piece_x1[k] <= p.x || s.piece_x0[k] > x_max) continue;
        if (s.piece_x0[k] > p.x && s.piece_x1[k] <= x_max) {
            w += dir;
            continue;
        }
        // The sub-piece at height p.y (on the piece's half-open range, as above).
        int j = 0;
        if (dir > 0) while (j + 1 < s.n_sub && s.sub_y(k, j + 1) <= p.y) ++j;
        else while (j + 1 < s.n_sub && p.y < s.sub_y(k, j + 1)) ++j;
        double fa = s.sub_y(k, j) - p.y, fb = s.sub_y(k, j + 1) - p.y;
        double ax[4], ay[4];
        if ((fa < 0) == (fb < 0) && fa != 0 && fb != 0) {  // cuts not monotone to rounding: the whole piece
            s.power_basis(ax, ay);
            if (monotone_crossing_within(ax, ay, p.y, s.split[k], s.split[k + 1], ya - p.y, yb - p.y, p.x, x_max))
                w += dir;
            continue;
        }
        if (s.sub_x1[k][j] <= p.x || s.sub_x0[k][j] > x_max) continue;
        if (s.sub_x0[k][j] > p.x && s.sub_x1[k][j] <= x_max) {
            w += dir;
            continue;
        }
        s.power_basis(ax, ay);
        if (monotone_crossing_within(ax, ay, p.y, s.sub_t(k, j), s.sub_t(k, j + 1), fa, fb, p.x, x_max)) w += dir;
    }
    return w;
}

// A fill's signed distance is +-|closest - p|; within ON_EDGE (pixels) of the edge the
// direction closest - p is lost to rounding (exactly 0 where a pixel centre lies on the
// edge, as on mcseem2's 45-degree segments through integer points), so its gradient takes
// the segment's normal, turned towards the inside (SdfArg::side). That is the two-sided
// derivative: across one edge the signed distance is linear. On a vertex, within ON_EDGE
// of two segments, it is a kink (the max or min of the two edges' signed distances), and
// its central derivative is the mean of the two segments' (SdfArg::item2): half each.
constexpr double ON_EDGE = 1e-7;

// Parabolic prefilter kernel: coverage of a half-plane at signed distance d (in units of
// the kernel radius, positive outside): 1/2 + (d^3 - 3d)/4 on [-1, 1]; and its slope.
VF_HD double kernel_coverage(double d) {
    if (d <= -1) return 1;
    if (d >= 1) return 0;
    return 0.5 + (d * d * d - 3 * d) * 0.25;
}

VF_HD double kernel_slope(double d) { return std::fabs(d) < 1 ? 0.75 * (d * d - 1) : 0.0; }

VF_HD bool winding_inside(int winding, int rule) {
    return rule == EVENODD ? (winding & 1) != 0 : winding != 0;
}

// ----------------------------------------------------------------------- strokes

VF_HD double point_line_segment_distance(Vec2 p, Vec2 a, Vec2 b) {
    Vec2 d = b - a;
    double l2 = dot(d, d);
    double t = l2 > 0 ? vclamp(dot(p - a, d) / l2, 0.0, 1.0) : 0.0;
    return distance(a + t * d, p);
}

VF_HD bool convex_contains(const Vec2* v, int n, Vec2 q) {
    bool pos = false, neg = false;
    for (int i = 0; i < n; ++i) {
        double c = cross(v[(i + 1) % n] - v[i], q - v[i]);
        pos |= c > 0;
        neg |= c < 0;
    }
    return !(pos && neg);
}

// A join polygon (vertex first, then its outer points): its two sides from the vertex are
// seams with the sweeps, so depth inside counts only the outer edges.
VF_HD double join_polygon_sdf(const Vec2* v, int n, Vec2 q) {
    double outer = 1e300, all = 1e300;
    for (int i = 0; i < n; ++i) {
        double d = point_line_segment_distance(q, v[i], v[(i + 1) % n]);
        all = vmin(all, d);
        if (i != 0 && i != n - 1) outer = vmin(outer, d);
    }
    return convex_contains(v, n, q) ? -outer : all;
}

// The outer edge of a bevel join (or of a miter join's bevel fallback), nullptr for any
// other end piece. Seam rule: the sweeps on either side of a bevel are no deeper than
// their distance to this edge. A sweep's depth is its distance to its offset curves, the
// bevel triangle's its distance to this edge, and on the seam between them (the sweep's
// end normal, at s from the vertex) the two differ: hw - s against (hw - s) cos(turn / 2),
// so the image jumped where a point crossed it. Bounded, the sweep is as deep as the
// triangle on the seam (the edge is the closer there), and near the vertex its depth is
// the true one (the bevel edge is the union's boundary). Round joins, miters within their
// limit, caps and butt ends already agree with the sweep on their seams.
VF_HD const Vec2* bevel_edge(const StrokeEnd& e) {
    return e.kind == StrokeEnd::POLYGON && e.n_poly == 3 ? e.poly + 1 : nullptr;
}

// Local frame of a square cap: s along the outward tangent from the end point, u across.
VF_HD void cap_frame(const StrokeEnd& e, Vec2 q, double& s, double& u) {
    Vec2 r = q - e.center;
    s = dot(r, e.axis);
    u = cross(e.axis, r);
}

// Half square s in [0, hw], |u| <= hw; its back edge (s = 0) is a seam with the sweep.
VF_HD double square_sdf(const StrokeEnd& e, Vec2 q, double hw) {
    double s, u;
    cap_frame(e, q, s, u);
    double au = std::fabs(u);
    if (s >= 0 && s <= hw && au <= hw) return -vmin(hw - s, hw - au);
    double ds = s < 0 ? -s : vmax(s - hw, 0.0), du = vmax(au - hw, 0.0);
    return std::sqrt(ds * ds + du * du);
}

VF_HD bool end_contains(const StrokeEnd& e, Vec2 q) {
    double hw = e.hw;
    switch (e.kind) {
        case StrokeEnd::DISK: return dot(q - e.center, q - e.center) <= hw * hw;
        case StrokeEnd::SQUARE: {
            double s, u;
            cap_frame(e, q, s, u);
            return s >= 0 && s <= hw && std::fabs(u) <= hw;
        }
        case StrokeEnd::POLYGON: return convex_contains(e.poly, e.n_poly, q);
        default: return false;
    }
}

VF_HD double end_sdf(const StrokeEnd& e, Vec2 q) {
    double hw = e.hw;
    switch (e.kind) {
        case StrokeEnd::DISK: return distance(q, e.center) - hw;
        case StrokeEnd::SQUARE: return square_sdf(e, q, hw);
        case StrokeEnd::POLYGON: return join_polygon_sdf(e.poly, e.n_poly, q);
        default: return 1e300;
    }
}

// Critical points of |B(t) - q| that have a normal: at an end where B' vanishes (a
// control point on the end point) every q is "critical", which would put a disk there,
// a round cap or join the style did not ask for. The limit tangent decides there, and
// its normal line has no area. (An interior cusp keeps its disk, as Skia's stroker does.)
VF_HD int sweep_critical_points(const Segment& s, Vec2 q, double* ts) {
    int n = seg_critical_points(s, q, ts);
    if (n == 0 || (ts[0] > 0 && ts[n - 1] < 1)) return n;
    double size2 = 0;
    for (int i = 1; i <= s.degree; ++i) size2 = vmax(size2, dot(s.p[i] - s.p[0], s.p[i] - s.p[0]));
    int m = 0;
    for (int i = 0; i < n; ++i) {
        bool end = ts[i] <= 0 || ts[i] >= 1;
        Vec2 d = seg_deriv(s, ts[i]);
        if (end && dot(d, d) <= 1e-18 * size2) continue;
        ts[m++] = ts[i];
    }
    return m;
}

// The critical point of a gently curved piece (StrokeSegment::simple): g(t) = (B - q).B'
// is increasing there, so a root exists iff g(0) <= 0 <= g(1); safeguarded Newton.
VF_HD int simple_critical_point(const Segment& s, Vec2 q, double* ts) {
    Vec2 a[4];  // B(t) - q = sum a[k] t^k
    seg_power_basis(s, q, a);
    int n = s.degree;
    auto eval = [&](double t, Vec2& b0, Vec2& b1, Vec2& b2) {  // B - q, B', B''
        b0 = a[n]; b1 = n * a[n]; b2 = (n * (n - 1)) * a[n];
        for (int k = n - 1; k >= 0; --k) {
            b0 = b0 * t + a[k];
            if (k >= 1) b1 = b1 * t + k * a[k];
            if (k >= 2) b2 = b2 * t + (k * (k - 1)) * a[k];
        }
    };
    Vec2 b0, b1, b2;
    eval(0, b0, b1, b2);
    double g0 = dot(b0, b1);
    eval(1, b0, b1, b2);
    double g1 = dot(b0, b1);
    if (g0 > 0 || g1 < 0) return 0;
    if (g0 == 0) { ts[0] = 0; return 1; }
    if (g1 == 0) { ts[0] = 1; return 1; }
    // The distance is stationary at the root: an error of 1e-9 in t moves it by ~1e-18.
    double lo = 0, hi = 1, t = g0 / (g0 - g1);
    for (int it = 0; it < 40; ++it) {
        eval(t, b0, b1, b2);
        double v = dot(b0, b1);
        if (v < 0) lo = t; else hi = t;
        double dv = dot(b1, b1) + dot(b0, b2);
        double next = dv > 0 ? t - v / dv : 0.5 * (lo + hi);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        bool done = std::fabs(next - t) < 1e-9 || hi - lo < 1e-9;
        t = next;
        if (done) break;
    }
    ts[0] = t;
    return 1;
}

VF_HD int stroke_critical_points(const StrokeSegment& ss, Vec2 q, double* ts) {
    return ss.simple ? simple_critical_point(ss.seg, q, ts) : sweep_critical_points(ss.seg, q, ts);
}

// Whether q is within `reach` of the segment's control-point hull's chord-frame box.
VF_HD bool near_segment(const StrokeSegment& ss, Vec2 q, double reach) {
    Vec2 r = q - ss.seg.p[0];
    double s = dot(r, ss.frame_u), n = cross(ss.frame_u, r);
    return s >= ss.s_min - reach && s <= ss.s_max + reach && n >= ss.n_min - reach && n <= ss.n_max + reach;
}

// The half width along the piece: its profile hw(t) (all equal without per-point widths).
VF_HD double item_hw(const StrokeSegment& s, double t) { return bez_scalar(s.hw, s.seg.degree, t); }

// Signed distance to the sweep's boundary from its critical points alone (offset curves):
// min over critical points of |B(t*) - q| - hw(t*); +huge when there are none.
VF_HD double sweep_sdf(const StrokeSegment& ss, Vec2 q, double* t_best = nullptr) {
    double ts[5];
    int n = stroke_critical_points(ss, q, ts);
    double best = 1e300;
    for (int i = 0; i < n; ++i) {
        double v = distance(seg_eval(ss.seg, ts[i]), q) - item_hw(ss, ts[i]);
        if (v < best) {
            best = v;
            if (t_best) *t_best = ts[i];
        }
    }
    return best;
}

// Whether q lies in the sweep of normals of half length hw(t) (see the top comment).
VF_HD bool sweep_contains(const StrokeSegment& ss, Vec2 q) {
    const Segment& s = ss.seg;
    if (s.degree == 1) {  // the rectangle (trapezoid) around the line: the normal through q is at t
        Vec2 d = s.p[1] - s.p[0];
        double l2 = dot(d, d);
        if (l2 <= 0) return false;
        double t = dot(q - s.p[0], d) / l2;
        return t >= 0 && t <= 1 && std::fabs(cross(d, q - s.p[0])) <= item_hw(ss, t) * std::sqrt(l2);
    }
    double ts[5];
    int n = stroke_critical_points(ss, q, ts);
    for (int i = 0; i < n; ++i) {
        double h = item_hw(ss, ts[i]);
        Vec2 r = seg_eval(s, ts[i]) - q;
        if (dot(r, r) <= h * h) return true;
    }
    return false;
}

VF_HD bool stroke_item_contains(const StrokeSegment& s, Vec2 q) {
    return end_contains(s.end, q) || end_contains(s.start, q) ||
           (near_segment(s, q, s.hw_max) && sweep_contains(s, q));
}

// Signed distance (stroke space) to this item's pieces. The butt end lines of free ends
// bound the sweep; other end normals are interior seams covered by a join or cap, and a
// bevel join's outer edge bounds the sweeps on both its sides (bevel_edge). `items`: the
// draw's stroke items, by global index (the join at this item's start is its prev's end).
VF_HD double stroke_item_sdf(const StrokeSegment* items, const StrokeSegment& s, Vec2 q, double limit,
                             SdfArg* arg = nullptr) {
    // Farther than hw + limit from the hull: the sweep cannot bring the distance under limit.
    double t = 0;
    double sd = near_segment(s, q, s.hw_max + limit) ? sweep_sdf(s, q, &t) : 1e300;
    SdfArg::Kind kind = SdfArg::SWEEP;
    int side = 0;
    if (s.butt_start || s.butt_end) {
        double dl = 1e300;
        int dl_side = 0;
        for (int k = 0; k < 2; ++k) {
            if (!(k == 0 ? s.butt_start : s.butt_end)) continue;
            Vec2 at = k == 0 ? s.seg.p[0] : seg_end(s.seg);
            Vec2 n = perp(seg_end_tangent(s.seg, k == 1));
            double h = k == 0 ? s.start.hw : s.end.hw;
            double v = point_line_segment_distance(q, at - h * n, at + h * n);
            if (v < dl) { dl = v; dl_side = k; }
        }
        double combined = sd <= 0 ? vmax(sd, -dl) : vmin(sd, dl);
        if (combined != sd) { kind = SdfArg::BUTT; side = dl_side; }
        sd = combined;
    }
    // the seam rule: inside the sweep, bevel edges at either end bound the depth
    if (sd <= 0 && (s.bevel_start || s.end.kind == StrokeEnd::POLYGON)) {
        for (int k = 0; k < 2; ++k) {
            const Vec2* edge = k == 0 ? (s.bevel_start ? bevel_edge(items[s.prev].end) : nullptr) : bevel_edge(s.end);
            if (!edge) continue;
            double e = -point_line_segment_distance(q, edge[0], edge[1]);
            if (e > sd) { sd = e; kind = SdfArg::SEAM; side = k; }
        }
    }
    double e0 = end_sdf(s.start, q), e1 = end_sdf(s.end, q);
    if (e0 < sd) { sd = e0; kind = SdfArg::END; side = 0; }
    if (e1 < sd) { sd = e1; kind = SdfArg::END; side = 1; }
    if (arg) {
        arg->kind = kind;
        arg->side = side;
        arg->t = t;
        if (kind == SdfArg::SWEEP) arg->closest = seg_eval(s.seg, t);
    }
    return sd;
}

// ----------------------------------------------------------------- whole draws
// The queries below take the draw's items to look at: all of them (AllItems), or those
// a tile lists (see scene/tiles.h). Fill winding numbers are computed by the caller.

struct AllItems {
    int n;
    VF_HD int size() const { return n; }
    VF_HD int operator[](int i) const { return i; }
    VF_HD bool may_reach(int, Vec2, double) const { return true; }
    VF_HD bool may_beat(int, Vec2, double) const { return true; }
};

VF_HD Vec2 to_stroke_space(const PreparedDraw& d, Vec2 p) {
    return d.metric_identity ? p : d.metric * p;
}

VF_HD int draw_winding_all(const SceneView& sc, const PreparedDraw& d, Vec2 p) {
    int w = 0;
    const PreparedSegment* segs = sc.fill_items.data() + d.first_item;
    for (int i = 0; i < d.n_items; ++i) w += ray_crossings(segs[i], p);
    return w;
}

// Sub-piece j of y-monotone piece k cut into n capsules of equal parameter length (n <=
// 64): pts[0..n] on the curve (power basis ax, ay; the ends' heights are the piece's cuts,
// sub_y), and, returned, how far the curve strays from each chord at most: dt^2 / 8 times
// the most |B''| on the sub-piece (B'' is linear in t, so that is at an end), with a
// margin for rounding. Tile lists (scene/tiles.cpp) and the per-tile fields
// (scene/field.cpp) bound a curve's parts by these.
VF_HD double sub_piece_capsules(const PreparedSegment& s, const double* ax, const double* ay, int k, int j, int n,
                                Vec2* pts) {
    const double ta = s.sub_t(k, j), tb = s.sub_t(k, j + 1);
    for (int i = 0; i <= n; ++i) {
        double t = i == 0 ? ta : i == n ? tb : ta + (tb - ta) * i / n;
        double x = ((ax[3] * t + ax[2]) * t + ax[1]) * t + ax[0];
        double y = i == 0 ? s.sub_y(k, j) : i == n ? s.sub_y(k, j + 1) : ((ay[3] * t + ay[2]) * t + ay[1]) * t + ay[0];
        pts[i] = {x, y};
    }
    double m = 0;
    if (s.seg.degree > 1)
        for (int e = 0; e < 2; ++e) {
            double t = e == 0 ? ta : tb;
            Vec2 b2{2 * ax[2] + 6 * ax[3] * t, 2 * ay[2] + 6 * ay[3] * t};
            m = vmax(m, length(b2));
        }
    const double dt = (tb - ta) / n;
    const double scale = 1 + vmax(vmax(std::fabs(s.box.x0), std::fabs(s.box.x1)), vmax(std::fabs(s.box.y0), std::fabs(s.box.y1)));
    return dt * dt / 8 * m * (1 + 1e-9) + 1e-12 * scale;
}

// Whether the curve lies `limit` or farther from p, for certain: its sub-pieces' boxes (see
// PreparedSegment::sub_y; exact ranges), then the halves of those that come closer, by de
// Casteljau, each bounded by its control points' box, down to DEPTH levels. A curve's
// closest point costs a quintic's roots; where many long curves pass near a pixel (30,000
// across a 64 px canvas: hundreds at each), most are set aside in a few splits.
VF_HD bool curve_farther(const PreparedSegment& s, Vec2 p, double limit) {
    constexpr int DEPTH = 6;
    const double l2 = limit * limit;
    for (int k = 0; k + 1 < s.n_split; ++k)
        for (int j = 0; j < s.n_sub; ++j) {
            double ya = s.sub_y(k, j), yb = s.sub_y(k, j + 1);
            if (distance2(Box{s.sub_x0[k][j], vmin(ya, yb), s.sub_x1[k][j], vmax(ya, yb)}, p) >= l2) continue;
            Segment stack[DEPTH + 1];
            int level[DEPTH + 1], n = 0;
            stack[n] = seg_part(s.seg, s.sub_t(k, j), s.sub_t(k, j + 1));
            level[n++] = 0;
            while (n > 0) {
                --n;
                const Segment c = stack[n];
                const int lv = level[n];
                Box b;
                for (int i = 0; i <= c.degree; ++i) expand(b, c.p[i]);
                if (distance2(b, p) >= l2) continue;
                if (lv == DEPTH) return false;
                seg_split(c, 0.5, stack[n], stack[n + 1]);
                level[n] = level[n + 1] = lv + 1;
                n += 2;
            }
        }
    return true;
}

// One segment of fill_distance: segment k of fill draw d (its index among the draw's
// items) measured from p, lowering `best` (and filling `arg`) where it is closer. (A curve
// is measured only where it may come within the distance so far, curve_farther: a long
// path's cost follows the pixels near each segment, not those in its box.) The per-tile
// fields (scene/field.h) call this too, so that both give the same distances and args.
VF_HD void fill_distance_step(const SceneView& sc, const PreparedDraw& d, int k, Vec2 p, double& best,
                              SdfArg* arg) {
    const PreparedSegment& s = sc.fill_items[d.first_item + k];
    double d2 = distance2(s.box, p);  // (on an edge, with arg: look for a second one)
    if (d2 >= best * best && !(arg && best < ON_EDGE && d2 < ON_EDGE * ON_EDGE)) return;
    if (s.seg.degree > 1 && curve_farther(s, p, arg && best < ON_EDGE ? ON_EDGE : best)) return;
    Closest c;
    if (s.seg.degree == 1) {
        Vec2 a = s.seg.p[0], e = s.seg.p[1] - a;
        double l2 = dot(e, e);
        c.t = l2 > 0 ? vclamp(dot(p - a, e) / l2, 0.0, 1.0) : 0.0;
        c.dist = distance(a + c.t * e, p);
    } else {
        c = seg_closest(s.seg, p);
    }
    if (arg && c.dist < ON_EDGE && best < ON_EDGE) {  // a vertex: keep both segments
        int keep = c.dist < best ? arg->item : d.first_item + k;
        double keep_t = c.dist < best ? arg->t : c.t;  // (stored as a float)
        if (c.dist < best) {
            best = c.dist;
            arg->item = d.first_item + k;
            arg->t = c.t;
            arg->closest = seg_eval(s.seg, c.t);
        }
        arg->item2 = keep;
        arg->t2 = (float)keep_t;
        return;
    }
    if (c.dist < best) {
        best = c.dist;
        if (arg) {
            arg->item2 = -1;
            arg->kind = SdfArg::SEGMENT;
            arg->item = d.first_item + k;
            arg->t = c.t;
            arg->closest = seg_eval(s.seg, c.t);
        }
    }
}

// Distance from p to the closest fill segment among items, or `limit` if none is closer.
template <class Items>
VF_HD double fill_distance(const SceneView& sc, const PreparedDraw& d, const Items& items, Vec2 p, double limit,
                     SdfArg* arg = nullptr) {
    double best = limit;
    for (int i = 0; i < items.size(); ++i) fill_distance_step(sc, d, items[i], p, best, arg);
    return best;
}

template <class Items>
VF_HD bool stroke_contains(const SceneView& sc, const PreparedDraw& d, const Items& items, Vec2 p) {
    Vec2 q = to_stroke_space(d, p);
    double hw = d.half_width;
    if (d.is_ellipse) {
        double lo, hi;
        if (ellipse_distance_bounds(d.ellipse, q, lo, hi)) {  // most samples: decided by the bounds
            if (lo > hw) return false;
            if (hi <= hw) return true;
        }
        Vec2 c;
        return ellipse_closest(d.ellipse, q, c) <= hw;
    }
    const StrokeSegment* all = sc.stroke_items.data() + d.first_item;
    for (int i = 0; i < items.size(); ++i) {
        if (!items.may_reach(i, p, 0)) continue;
        const StrokeSegment& s = all[items[i]];
        if (p.x < s.box.x0 || p.x > s.box.x1 || p.y < s.box.y0 || p.y > s.box.y1) continue;
        if (stroke_item_contains(s, q)) return true;
    }
    return false;
}

// Signed distance in pixels to the stroke (negative inside), clamped to [-limit, limit].
template <class Items>
VF_HD double stroke_sdf(const SceneView& sc, const PreparedDraw& d, const Items& items, Vec2 p, double limit,
                  SdfArg* arg = nullptr) {
    Vec2 q = to_stroke_space(d, p);
    double hw = d.half_width;
    double sd = 1e300;
    if (d.is_ellipse) {
        double lo, hi;
        // without derivatives wanted, a sample farther than the clamp needs no closest point
        if (!arg && ellipse_distance_bounds(d.ellipse, q, lo, hi) && (lo - hw) * d.metric_scale >= limit)
            return limit;
        Vec2 c;
        sd = ellipse_closest(d.ellipse, q, c) - hw;
        if (arg) {
            arg->kind = SdfArg::ELLIPSE;
            arg->closest = c;
        }
    } else {
        const StrokeSegment* all = sc.stroke_items.data() + d.first_item;
        SdfArg local;
        for (int i = 0; i < items.size(); ++i) {
            // Searched within the best found so far, not just within the limit: an item
            // farther than that cannot win (where 30,000 long curves pass near every pixel,
            // each pixel solved the quintic of hundreds of them). Exact: a box and the
            // sweep's gate bound an item's distance from below, whatever their sign.
            double reach = vmin(limit, sd * d.metric_scale);
            if (!items.may_reach(i, p, reach)) continue;
            // (a bound of the item's signed distance below, where the items carry one: an
            // item it puts at sd or farther cannot lower sd, and is not read)
            if (!items.may_beat(i, q, sd)) continue;
            Box b = grown(all[items[i]].box, reach);
            if (p.x < b.x0 || p.x > b.x1 || p.y < b.y0 || p.y > b.y1) continue;
            double v = stroke_item_sdf(sc.stroke_items.data(), all[items[i]], q, reach / d.metric_scale,
                                       arg ? &local : nullptr);
            if (v < sd) {
                sd = v;
                if (arg) {
                    *arg = local;
                    arg->item = d.first_item + items[i];
                }
            }
            // As deep as the clamp below: whatever else is near, the answer is -limit (and
            // its kernel slope 0). A stroke 10^7 px wide measured all its items per pixel.
            if (sd * d.metric_scale <= -limit) break;
        }
    }
    return vclamp(sd * d.metric_scale, -limit, limit);
}

VF_HD double ellipse_fill_sdf(const PreparedDraw& d, Vec2 p, double limit, SdfArg* arg = nullptr) {
    double lo, hi;
    // without derivatives wanted, a sample farther than the clamp needs no closest point
    if (!arg && ellipse_distance_bounds(d.ellipse, p, lo, hi) && lo >= limit)
        return ellipse_contains(d.ellipse, p) ? -limit : limit;
    Vec2 c;
    double dist = vmin(ellipse_closest(d.ellipse, p, c), limit);
    if (arg) {
        arg->kind = SdfArg::ELLIPSE;
        arg->closest = c;
    }
    return ellipse_contains(d.ellipse, p) ? -dist : dist;
}

}  // namespace vf
