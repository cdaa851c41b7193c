// The scene as the core sees it: flat arrays in (structure of arrays, filled by the
// Python side, all geometry already in pixel space), and the prepared form the samplers
// read (segments with their control points, bounds, joins, paints).
//
// Names: a fill or stroke's colour source (solid, linear or radial gradient) is a paint
// in the core and in the arrays Python hands it (the "paints" and "paint_params" tables,
// as vello calls them): "paint" is the painterly command elsewhere in vecfit, and the
// SVG's word for a fill or stroke value in the Scene and the SVG reader.
#pragma once

#include <cstdint>
#include <vector>

#include "common/bezier.h"
#include "common/ellipse.h"
#include "common/portable.h"

namespace vf {

enum ShapeKind : int32_t { SHAPE_PATH = 0, SHAPE_ELLIPSE = 1 };
enum DrawKind : int32_t { DRAW_FILL = 0, DRAW_STROKE = 1 };
enum FillRule : int32_t { NONZERO = 0, EVENODD = 1 };
enum Cap : int32_t { CAP_BUTT = 0, CAP_ROUND = 1, CAP_SQUARE = 2 };
enum Join : int32_t { JOIN_MITER = 0, JOIN_ROUND = 1, JOIN_BEVEL = 2 };
enum PaintKind : int32_t { PAINT_SOLID = 0, PAINT_LINEAR = 1, PAINT_RADIAL = 2 };

// Column layouts of the input tables (row-major, one row per item). These, the enums above
// and the tables' keys are what _core.layout() exports to Python (python/bind_render.cpp).
constexpr int POINT_COLS = 2;     // x, y
constexpr int SEGMENT_COLS = 5;   // degree, point index of each control point (-1 unused)
constexpr int SUBPATH_COLS = 3;   // first segment, segment count, closed (0/1)
constexpr int SHAPE_COLS = 4;     // kind, first subpath, subpath count, ellipse index
constexpr int ELLIPSE_COLS = 6;   // cx, cy, a, b, c, d: ellipse {c + (a b; c d)(cos, sin)}
constexpr int DRAW_COLS = 8;      // shape, kind, fill rule, paint, layer, cap, join, per-point widths (0/1)
constexpr int DRAW_FCOLS = 6;     // stroke width (unused with per-point widths), miter limit, metric (a b c d)
constexpr int PAINT_COLS = 3;     // kind, first stop, stop count
constexpr int PAINT_FCOLS = 11;   // pixel->paint affine (6), then solid rgba | x1 y1 x2 y2 | cx cy r fx fy
constexpr int STOP_COLOR_COLS = 4;  // straight RGBA
// point_widths, stop_offsets, layer_parents and layer_opacity: one value per row.

struct SceneArrays {
    const float* points = nullptr;       int n_points = 0;     // [P, 2]
    // Full stroke width per point, in stroke-space units (as the draw's uniform width),
    // for stroke draws with per-point widths; empty when no draw has them.
    const float* point_widths = nullptr; int n_point_widths = 0;  // [P] or [0]
    const int32_t* segments = nullptr;   int n_segments = 0;   // [G, SEGMENT_COLS]
    const int32_t* subpaths = nullptr;   int n_subpaths = 0;   // [B, SUBPATH_COLS]
    const int32_t* shapes = nullptr;     int n_shapes = 0;     // [S, SHAPE_COLS]
    const float* ellipses = nullptr;     int n_ellipses = 0;   // [E, ELLIPSE_COLS]
    const int32_t* draws = nullptr;      int n_draws = 0;      // [D, DRAW_COLS]
    const float* draw_params = nullptr;                        // [D, DRAW_FCOLS]
    const int32_t* paints = nullptr;    int n_paints = 0;    // [Q, PAINT_COLS]
    const float* paint_params = nullptr;                       // [Q, PAINT_FCOLS]
    const float* stop_offsets = nullptr; int n_stops = 0;      // [T]
    const float* stop_colors = nullptr;                        // [T, 4] straight RGBA
    const int32_t* layer_parents = nullptr; int n_layers = 0;  // [L]; layer 0 is the root
    const float* layer_opacity = nullptr;                      // [L]
};

// A path segment as its strokes are built from it: its control points (pixel space) and
// where they came from (for gradients).
struct SegmentSource {
    Segment seg;
    int32_t point_index[4] = {-1, -1, -1, -1};
};

// A segment ready for sampling, with where its control points came from (for gradients).
// (576 bytes: ranges are floats rounded outwards, the power basis is computed where a
// root needs it; a path of 300,000 segments holds one of these per segment.)
struct PreparedSegment {
    Segment seg;
    int32_t point_index[4] = {-1, -1, -1, -1};
    Box box;
    double split[4];        // 0, y-extrema in (0,1) ascending, 1: y-monotone pieces
    double split_y[4];      // y at each split
    float piece_x0[3], piece_x1[3];  // x range of each piece (of the curve, see seg_bbox)
    int n_split = 2;
    // Each y-monotone piece cut into n_sub sub-pieces of equal parameter length (curves;
    // lines keep one; see sub_t), with their y (sub_y) and x ranges: a ray crossing is
    // decided by the one sub-piece at the ray's height, whose x range is a few times
    // narrower than the piece's (no root to solve for most samples) and whose parameter
    // range brackets the root tightly (ray_crossings). Eight, not four: a fit lengthens its
    // curves, widening the ranges, and the root solves grew with them (DESIGN.md).
    static constexpr int SUB = 8;
    int n_sub = 1;
    double sub_cut[3][SUB - 1];  // y at the cuts inside each piece
    float sub_x0[3][SUB], sub_x1[3][SUB];
    VF_HD double sub_t(int k, int j) const {
        return j == n_sub ? split[k + 1] : split[k] + (split[k + 1] - split[k]) * j / n_sub;
    }
    // y at cut j of piece k: its ends (j = 0, n_sub) are the piece's own.
    VF_HD double sub_y(int k, int j) const {
        return j == 0 ? split_y[k] : j == n_sub ? split_y[k + 1] : sub_cut[k][j - 1];
    }
    // Power-basis coefficients of x(t) and y(t), for roots.
    VF_HD void power_basis(double* ax, double* ay) const {
        seg_axis_poly(seg, 0, ax);
        seg_axis_poly(seg, 1, ay);
    }
};

// Stroke geometry at a segment's end: the join with the next segment, or the cap.
// (Fields in order of size: 112 bytes, two per stroke item.)
struct StrokeEnd {
    Vec2 center;            // disk / square centre
    Vec2 axis{1, 0};        // square: unit direction of one side pair
    Vec2 poly[4];           // polygon (bevel triangle or miter quadrilateral), convex
    // Half width of this end's piece (stroke space): the draw's, or with per-point widths
    // the vertex's. Also set for butt ends (kind NONE), whose end line it bounds.
    double hw = 0;
    int32_t width_index = -1;  // per-point widths: the point whose width hw is (gradients)
    enum Kind : int8_t { NONE = 0, DISK, SQUARE, POLYGON } kind = NONE;
    int8_t n_poly = 0;
};

// A stroke segment in stroke space (pixel space mapped by the draw's metric), with the
// end pieces that belong to it: the join or cap after it, and the cap before it when it
// starts an open subpath.
struct StrokeSegment {
    Segment seg;           // in stroke space
    double t0 = 0, t1 = 1; // the part of the source segment this item is (curves are split
                           // into short pieces: tighter bounds, fewer roots to find)
    StrokeEnd start, end;
    Box box;               // pixel-space bounds of everything above, widened by the half width
    // The segment's control points in the frame of its chord (origin p0, unit axis u):
    // a tighter bound than the box, which spares most samples the quintic.
    Vec2 frame_u{1, 0};
    double s_min = 0, s_max = 0, n_min = 0, n_max = 0;
    // Half widths (stroke space) at the piece's control points: the width profile is a
    // Bézier of the same degree, hw(t) = sum hw[i] b_i(t) (per-point widths; otherwise all
    // equal to the draw's half width). hw_max bounds it (convex hull property).
    double hw[4] = {0, 0, 0, 0};
    double hw_max = 0;
    int32_t source = -1;   // index into PreparedScene::segments (its path segment)
    int32_t next = -1;     // the stroke item after the join at this item's end (index into stroke_items)
    int32_t prev = -1;     // the stroke item whose end joins this item's start (index into stroke_items)
    bool butt_start = false, butt_end = false;  // free end with a butt cap: an edge of the stroke
    bool bevel_start = false;  // the join at this item's start (prev's end) is a bevel: seam rule
    // Gently curved (radius of curvature above the piece's length plus its reach): the
    // distance to any point in reach has at most one critical point on the piece.
    bool simple = false;
};

struct PreparedDraw {
    int32_t shape = 0, kind = DRAW_FILL, fill_rule = NONZERO, paint = 0, layer = 0;
    int32_t cap = CAP_BUTT, join = JOIN_MITER;
    double half_width = 0, miter_limit = 4;  // per-point widths: the largest half width
    bool varying = false;       // stroke with per-point widths (StrokeSegment::hw, StrokeEnd::hw)
    Mat2 metric, metric_inv;    // pixel -> stroke space and back
    bool metric_identity = true;
    double metric_scale = 1;    // pixel length per stroke-space length (geometric mean)
    // Path draws: fill segments (with closing lines for open subpaths) or stroke segments.
    int first_item = 0, n_items = 0;   // into PreparedScene::fill_items or stroke_items
    EllipseFrame ellipse;               // ellipse draws (in stroke space for strokes)
    bool is_ellipse = false;
    int ellipse_row = -1;               // its input row: pixel-space centre and axes
    Vec2 ellipse_center;
    Mat2 ellipse_axes;
    Box box;                            // pixel-space bounds of what the draw can cover
};

struct PreparedPaint {
    int32_t kind = PAINT_SOLID;
    Affine to_paint;            // pixel -> paint space
    double rgba[4] = {0, 0, 0, 0};
    double g[5] = {0, 0, 0, 0, 0};
    int first_stop = 0, n_stops = 0;
};

struct PreparedScene {
    // Every path segment (pixel space) where some draw strokes a path (the stroke items
    // refer to them, StrokeSegment::source); else empty. Fills keep their own, prepared.
    std::vector<SegmentSource> segments;
    std::vector<double> point_hw;            // per-point half widths (as given: clamp at 0 to use), or empty
    std::vector<PreparedSegment> fill_items; // per fill draw: its segments and closing lines
    std::vector<StrokeSegment> stroke_items; // per stroke draw
    std::vector<PreparedDraw> draws;
    std::vector<PreparedPaint> paints;
    std::vector<double> stop_offsets;
    std::vector<double> stop_colors;          // straight RGBA
    std::vector<int32_t> layer_parent;
    std::vector<double> layer_opacity;
    std::vector<int32_t> layer_depth;
    struct SceneView view() const;
};

// The prepared scene as the per-sample code reads it: views of its arrays, in host memory
// (PreparedScene::view) or in device memory (a CUDA build's copy).
struct SceneView {
    Span<SegmentSource> segments;
    Span<double> point_hw;
    Span<PreparedSegment> fill_items;
    Span<StrokeSegment> stroke_items;
    Span<PreparedDraw> draws;
    Span<PreparedPaint> paints;
    Span<double> stop_offsets, stop_colors;
    Span<int32_t> layer_parent;
    Span<double> layer_opacity;
    Span<int32_t> layer_depth;
};

inline SceneView PreparedScene::view() const {
    return {span_of(segments),     span_of(point_hw),     span_of(fill_items),   span_of(stroke_items),
            span_of(draws),        span_of(paints),       span_of(stop_offsets), span_of(stop_colors),
            span_of(layer_parent), span_of(layer_opacity), span_of(layer_depth)};
}

// A segment with its bounds and y-monotone pieces; idx: its control points' indices or null.
PreparedSegment prepare_segment(const Segment& s, const int32_t* idx);

// Validates the arrays (indices in range) and builds the prepared scene. Throws
// std::invalid_argument with a message on malformed input.
PreparedScene prepare_scene(const SceneArrays& a);

}  // namespace vf
