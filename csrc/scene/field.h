// The analytical prefilter's long fill entries, a tile at a time (the CPU passes; issue 28):
// an entry's signed distance (and where it came from) at every sample of a tile, computed
// segment by segment rather than sample by sample, so that its cost follows the pixels
// each segment reaches.
//
// Sample by sample (entry_sdf), each of a tile's samples goes through every segment the
// tile lists: a path of 30,000 cubics across a 64 px canvas lists thousands in each tile,
// hundreds of which pass within a pixel of each sample. Here, per entry:
//   * winding numbers: the same path as tile_winding (scene/tiles.h), counted a row of
//     samples at a time (the analytical samples lie on a grid: strata centres): the
//     vertical leg's crossings add to every row at or below them, and each crossing of a
//     sample row by a segment adds to the samples on its left (one root per crossing at
//     most, none where the crossing's x range holds no sample);
//   * distances: each curve's part near the tile is cut into pieces of about a pixel, each
//     bounded by the box of its control points in its chord's frame (tight for a short
//     piece); a first sweep finds each sample's nearest bound, whose segment's distance
//     d* the sample then measures exactly; a second sweep measures, in the tile's order of
//     segments, only the segments some piece of which may come within d* (or ON_EDGE),
//     with the same step as fill_distance (fill_distance_step). The distance and its
//     SdfArg are then entry_sdf's: the closest segment is the first one in order at the
//     least distance, and a segment farther than d* can neither be it nor change it.
// The winding numbers differ from tile_winding's only for a sample within rounding of a
// curve (a crossing's side is decided by the crossing's x, not a bracket per sample),
// where the coverage is 1/2 either way; tests/unit/renderer/test_long_paths.py compares
// the two on every entry (field_min_items = 0).
#pragma once

#include <cmath>
#include <vector>

#include "scene/coverage.h"
#include "scene/scene.h"
#include "scene/tiles.h"

namespace vf {

// Entries listing at least this many segments in a tile are computed here (see
// field_min_items_ref; a test hook sets it to 0 to compare every entry).
int& field_min_items_ref();

// The analytical samples of one tile: N x N strata centres per pixel, at the positions
// pixel_forward and pixel_backward use, as a grid of columns and rows (each sorted).
struct SampleGrid {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0, N = 1;
    std::vector<double> col_x, row_y;
    std::vector<int> index;  // [row * columns + col]: the sample's index among the tile's (see tile_sample)
    std::vector<int> col_pixel, row_pixel;  // the pixel column (row) of each column (row) of samples
    void build(const TileView& bins, int tile, int width, int height, int N, double R);
    int count() const { return (x1 - x0) * (y1 - y0) * N * N; }
    int at(int row, int col) const { return index[(size_t)row * col_x.size() + col]; }
    // The first column (row) at or after x (y): lower_bound, from a guess on an even grid.
    int first_col(double x) const { return first(col_x, x, col0_, col_step_); }
    int first_row(double y) const { return first(row_y, y, row0_, row_step_); }
    // The first column (row) after x (y): upper_bound.
    int after_col(double x) const { return after(col_x, x, col0_, col_step_); }
    int after_row(double y) const { return after(row_y, y, row0_, row_step_); }

  private:
    double col0_ = 0, col_step_ = 1, row0_ = 0, row_step_ = 1;  // (steps stored inverted)
    static int guess(const std::vector<double>& v, double x, double v0, double inv_step) {
        double k = (x - v0) * inv_step;
        return k < 0 ? 0 : k >= (double)v.size() ? (int)v.size() : (int)k;
    }
    static int first(const std::vector<double>& v, double x, double v0, double step) {
        int i = guess(v, x, v0, step), n = (int)v.size();
        while (i > 0 && v[i - 1] >= x) --i;
        while (i < n && v[i] < x) ++i;
        return i;
    }
    static int after(const std::vector<double>& v, double x, double v0, double step) {
        int i = guess(v, x, v0, step), n = (int)v.size();
        while (i > 0 && v[i - 1] > x) --i;
        while (i < n && v[i] <= x) ++i;
        return i;
    }
};

// A stroke item's signed distance bounded from below, for the long stroke entries: the
// tile's items are listed with their boxes, but where a long path's pieces crowd (30,000
// curves across a 64 px canvas: 19,000 pieces listed in a tile, 2,000 of whose boxes
// hold each pixel) reading each piece whose box holds a sample (448 bytes, scattered over
// hundreds of megabytes) was most of the analytical pass. These records (56 bytes, one
// per stroke item, in item order, made once per pass) set aside the pieces that cannot
// lower a sample's distance so far:
//   * the sweep and the butt ends: farther than the distance from q to the box of the
//     piece's control points in its chord's frame (StrokeSegment::frame_u, s_min...),
//     less `sweep` (the most half width at the piece's points and ends);
//   * a cap at the start: the same box, less its reach from its anchor (the start point,
//     a corner of the box's hull: a disk reaches hw, a half square hw sqrt(2));
//   * the join or cap at the end: the distance from its anchor (the vertex), less its
//     reach (a join polygon's farthest corner; a convex piece anchored on its boundary
//     lies within its reach of the anchor, and the depth inside it is no more than the
//     reach less the distance from the anchor, along the ray from the anchor).
// The seam rule only raises a distance. Floats: each side is rounded outwards, and what
// the floats' frame and anchor may be off is added to the reaches (make_stroke_bound)
// and, at the query, in proportion to how far q lies from the piece (stroke_bound_below).
struct StrokeBound {
    double ox = 0, oy = 0;            // the piece's start point (stroke space)
    float ux = 1, uy = 0;             // its chord's direction
    float s0 = 0, s1 = 0, n0 = 0, n1 = 0;  // its control points' box in that frame, from o
    float sweep = INFINITY;           // the sweep's, the butt ends' and a start cap's reach past the box
    float ex = 0, ey = 0;             // the end piece's anchor, from o
    float end_reach = -1;             // how far the end piece reaches from it (< 0: none)
};

StrokeBound make_stroke_bound(const StrokeSegment& s);

// A lower bound of stroke_item_sdf(.., s, q, ..) for any limit (stroke space).
inline double stroke_bound_below(const StrokeBound& b, Vec2 q) {
    const double rx = q.x - b.ox, ry = q.y - b.oy;
    const double s = rx * b.ux + ry * b.uy, n = b.ux * ry - b.uy * rx;
    const double ds = vmax(vmax(b.s0 - s, s - b.s1), 0.0), dn = vmax(vmax(b.n0 - n, n - b.n1), 0.0);
    double lb = std::sqrt(ds * ds + dn * dn) - b.sweep;
    if (b.end_reach >= 0) {
        const double ex = rx - b.ex, ey = ry - b.ey;
        lb = vmin(lb, std::sqrt(ex * ex + ey * ey) - b.end_reach);
    }
    // the floats' frame turned by up to about 2^-23 (rounding), and the doubles' own rounding
    return lb - (2.5e-7 * (std::fabs(rx) + std::fabs(ry)) +
                 1e-12 * (1 + std::fabs(q.x) + std::fabs(q.y) + std::fabs(rx) + std::fabs(ry)));
}

// The stroke bounds of every stroke item of the scene, where some tile lists a stroke's
// items long enough for the fields (else empty): made once per pass, on `threads`.
std::vector<StrokeBound> stroke_bounds(const SceneView& sc, const TileView& bins, int threads);


// The fields of one tile's long fill and stroke entries, reused from tile to tile by a worker.
class TileFields {
  public:
    // Computes every fill entry of the tile that lists at least field_min_items segments
    // (none with brute_force), and where `bounds` are given (stroke_bounds) every stroke
    // entry as long, with their SdfArgs when `args` (the backward pass).
    void compute(const SceneView& sc, const TileView& bins, int tile, const SampleGrid& grid, double r, bool args,
                 const StrokeBound* bounds = nullptr);
    // The view the per-sample code reads (empty where no entry was computed).
    FieldView view() const;

  private:
    static constexpr int MAX_CAPSULES = 64;
    // A long stroke entry's items that may reach the tile's samples: the box its tile
    // list gives (LocalItem's), the item, and its bound (copied: read by every sample near).
    struct StrokeItem {
        float x0, y0, x1, y1;
        int item;
    };
    // A cell's list of them (indices into stroke_items_, in the entry's order), as
    // stroke_sdf takes its items (see LocalItems).
    struct CellItems {
        const int* index;
        int n;
        const StrokeItem* items;
        const StrokeBound* bounds;
        int size() const { return n; }
        int operator[](int i) const { return items[index[i]].item; }
        bool may_reach(int i, Vec2 p, double reach) const {  // (LocalItems::may_reach)
            const StrokeItem& l = items[index[i]];
            return p.y >= l.y0 - reach && p.y <= l.y1 + reach && p.x >= l.x0 - reach && p.x <= l.x1 + reach;
        }
        bool may_beat(int i, Vec2 q, double sd) const { return stroke_bound_below(bounds[index[i]], q) < sd; }
    };
    struct Piece {     // a capsule of a curve near the tile's samples (28 bytes: a long path's
                       // tile holds over 100,000 of them)
        int li;        // its segment's index in the entry's local items
        float a[2], v[2];  // the chord from a to a + v, relative to origin_
        float inv2;    // 1 / |v|^2 (0 for a point)
        float h;       // how far the curve strays from the chord, with margins for rounding
    };
    void compute_entry(const SceneView& sc, const TileView& bins, int tile, const TileEntry& e, const SampleGrid& g,
                       double r, bool args, double* sd, SdfArg* arg);
    void compute_stroke(const SceneView& sc, const TileView& bins, const TileEntry& e, const SampleGrid& g, double r,
                        const StrokeBound* bounds, double* sd, SdfArg* arg);
    void scan(const SceneView& sc, const TileView& bins, int tile, const TileEntry& e, const SampleGrid& g, double r);

    int n_ = 0, slots_ = 0, tile_ = -1;
    Vec2 origin_;  // pieces' coordinates are relative to it (the tile's first sample)
    bool args_ = false;
    std::vector<int> slot_;
    std::vector<double> sd_;
    std::vector<SdfArg> arg_;
    // scratch
    std::vector<int> winding_, row_add_, leg_;
    std::vector<Piece> pieces_;
    std::vector<double> bound_, dstar_, best_;
    std::vector<int> nearest_, stamp_;
    std::vector<StrokeItem> stroke_items_;
    std::vector<StrokeBound> stroke_bounds_;
    std::vector<int> cell_start_, cell_index_, item_cells_;
    std::vector<double> cell_x0_, cell_x1_, cell_y0_, cell_y1_;
};

}  // namespace vf
