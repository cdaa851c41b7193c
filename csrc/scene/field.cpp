// The analytical prefilter's long fill entries, a tile at a time (field.h): winding numbers
// by rows of samples, distances by pieces of curve and the samples near each.
#include "scene/field.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "common/float_bounds.h"
#include "common/thread_pool.h"

namespace vf {

int& field_min_items_ref() {
    // Measured on tiger and boston (2x2, both passes): entries this long cost about the
    // same either way; below, the per-tile set-up costs more than it saves.
    static int n = 16;
    return n;
}

namespace {

// About how long a capsule is (pixels), and the most a sub-piece is cut into: a capsule a
// pixel long lies within about 1 / (8 x radius of curvature) of its curve, which sets
// aside nearly every curve that is not the closest.
constexpr double PIECE = 1.0;

double box_distance2(const Box& a, const Box& b) {
    double dx = vmax(vmax(a.x0 - b.x1, b.x0 - a.x1), 0.0);
    double dy = vmax(vmax(a.y0 - b.y1, b.y0 - a.y1), 0.0);
    return dx * dx + dy * dy;
}

}  // namespace

StrokeBound make_stroke_bound(const StrokeSegment& s) {
    StrokeBound b;
    const Vec2 o = s.seg.p[0];
    b.ox = o.x;
    b.oy = o.y;
    b.ux = (float)s.frame_u.x;
    b.uy = (float)s.frame_u.y;
    b.s0 = float_below(s.s_min);
    b.s1 = float_above(s.s_max);
    b.n0 = float_below(s.n_min);
    b.n1 = float_above(s.n_max);
    // the control points as the floats' frame sees them: off by up to about 2^-23 of their
    // distance from o (the frame's rounding) each way
    const double extent = 1.5 * (vmax(std::fabs(s.s_min), std::fabs(s.s_max)) + vmax(std::fabs(s.n_min), std::fabs(s.n_max)));
    // An end piece's anchor (a point its reach is measured from) and reach (see StrokeBound).
    auto piece = [](const StrokeEnd& e, Vec2& anchor) -> double {
        switch (e.kind) {
            case StrokeEnd::DISK: anchor = e.center; return e.hw;
            case StrokeEnd::SQUARE: anchor = e.center; return e.hw * 1.41421357;
            case StrokeEnd::POLYGON: {
                anchor = e.poly[0];
                double r = 0;
                for (int i = 1; i < e.n_poly; ++i) r = vmax(r, distance(e.poly[i], anchor));
                return r;
            }
            default: return -1;
        }
    };
    double sweep = vmax(s.hw_max, vmax(s.start.hw, s.end.hw));
    Vec2 anchor;
    double reach = piece(s.start, anchor);
    if (reach >= 0) sweep = vmax(sweep, reach + distance(anchor, o));  // (the anchor is o itself)
    b.sweep = float_above(sweep + 2.5e-7 * extent);
    reach = piece(s.end, anchor);
    if (reach >= 0) {
        const Vec2 a = anchor - o;
        b.ex = (float)a.x;
        b.ey = (float)a.y;
        const double off = distance(Vec2{b.ex, b.ey}, a);  // the float anchor's rounding
        b.end_reach = float_above(reach + off + 1e-7 * (std::fabs(a.x) + std::fabs(a.y)));
    }
    return b;
}

std::vector<StrokeBound> stroke_bounds(const SceneView& sc, const TileView& bins, int threads) {
    std::vector<StrokeBound> out;
    const int min_items = field_min_items_ref();
    bool any = false;
    for (size_t k = 0; k < bins.entries.size() && !any; ++k) {
        const TileEntry& e = bins.entries[k];
        const PreparedDraw& d = sc.draws[e.draw];
        any = d.kind == DRAW_STROKE && !d.is_ellipse && e.winding == 0 && e.count >= min_items;
    }
    if (!any) return out;
    const int n = (int)sc.stroke_items.size();
    out.resize(n);
    constexpr int CHUNK = 4096;
    ThreadPool::instance().parallel_for((n + CHUNK - 1) / CHUNK, threads, [&](int c, int) {
        for (int i = c * CHUNK; i < std::min(n, (c + 1) * CHUNK); ++i) out[i] = make_stroke_bound(sc.stroke_items[i]);
    });
    return out;
}

void SampleGrid::build(const TileView& bins, int tile, int width, int height, int samples, double R) {
    N = samples;
    const int tx = tile % bins.nx, ty = tile / bins.nx;
    x0 = tx * TILE;
    y0 = ty * TILE;
    x1 = std::min(width, x0 + TILE);
    y1 = std::min(height, y0 + TILE);
    struct Line {
        double v;
        int pixel, sub;
    };
    std::vector<Line> lines;
    std::vector<int> sub, row_sub;
    auto axis = [&](int a0, int a1, std::vector<double>& pos, std::vector<int>& pixel, std::vector<int>& sub) {
        lines.clear();
        for (int a = a0; a < a1; ++a)
            for (int i = 0; i < N; ++i) {
                double f = (i + 0.5) / N;  // the strata centres of pixel_forward and pixel_backward,
                double d = R * (2 * f - 1);  // computed as they compute them
                lines.push_back({a + 0.5 + d, a, i});
            }
        std::stable_sort(lines.begin(), lines.end(), [](const Line& a, const Line& b) { return a.v < b.v; });
        pos.resize(lines.size());
        pixel.resize(lines.size());
        sub.resize(lines.size());
        for (size_t k = 0; k < lines.size(); ++k) {
            pos[k] = lines[k].v;
            pixel[k] = lines[k].pixel;
            sub[k] = lines[k].sub;
        }
    };
    axis(x0, x1, col_x, col_pixel, sub);
    axis(y0, y1, row_y, row_pixel, row_sub);
    const size_t cols = col_x.size();
    index.resize(cols * row_y.size());
    for (size_t row = 0; row < row_y.size(); ++row)
        for (size_t col = 0; col < cols; ++col)
            index[row * cols + col] =
                ((row_pixel[row] - y0) * (x1 - x0) + (col_pixel[col] - x0)) * N * N + row_sub[row] * N + sub[col];
    auto spacing = [](const std::vector<double>& v, double& v0, double& inv_step) {
        v0 = v.front();
        inv_step = v.size() > 1 && v.back() > v.front() ? (double)(v.size() - 1) / (v.back() - v.front()) : 1.0;
    };
    spacing(col_x, col0_, col_step_);
    spacing(row_y, row0_, row_step_);
}

void TileFields::compute(const SceneView& sc, const TileView& bins, int tile, const SampleGrid& grid, double r,
                         bool args, const StrokeBound* bounds) {
    const int count = bins.count(tile);
    const TileEntry* es = bins.begin(tile);
    const int min_items = field_min_items_ref();
    n_ = grid.count();
    args_ = args;
    tile_ = tile;
    slot_.assign(count, -1);
    int slots = 0;
    // Entries behind an opaque one that covers every sample of the tile are never reached
    // (the forward pass stops at an opaque sample; without layers the backward pass at the
    // second opaque draw, collect_hits_analytic): a fill under a stroke 10^7 px wide.
    const Box area{grid.col_x.front(), grid.row_y.front(), grid.col_x.back(), grid.row_y.back()};
    int covering = 0;
    const bool no_layers = sc.layer_parent.size() <= 1;
    for (int k = count - 1; k >= 0 && covering < (args ? 2 : 1); --k) {
        const TileEntry& e = es[k];
        const PreparedDraw& d = sc.draws[e.draw];
        if (d.kind == DRAW_FILL && !d.is_ellipse && e.count >= min_items) slot_[k] = slots++;
        if (bounds && d.kind == DRAW_STROKE && !d.is_ellipse && e.winding == 0 && e.count >= min_items)
            slot_[k] = slots++;
        const PreparedPaint& paint = sc.paints[d.paint];
        const Box reach = grown(d.box, r);
        const bool covers_all = !d.is_ellipse && (d.kind == DRAW_STROKE ? e.winding != 0 :
                                                  e.count == 0 && winding_inside(e.winding, d.fill_rule));
        if (covers_all && no_layers && paint.kind == PAINT_SOLID && paint.rgba[3] >= 1 && reach.x0 <= area.x0 &&
            reach.y0 <= area.y0 && reach.x1 >= area.x1 && reach.y1 >= area.y1)
            ++covering;
    }
    slots_ = slots;
    if (slots == 0) return;
    sd_.resize((size_t)slots * n_);
    if (args) arg_.assign((size_t)slots * n_, SdfArg{});
    for (int k = 0; k < count; ++k) {
        if (slot_[k] < 0) continue;
        double* sd = sd_.data() + (size_t)slot_[k] * n_;
        SdfArg* arg = args ? arg_.data() + (size_t)slot_[k] * n_ : nullptr;
        if (sc.draws[es[k].draw].kind == DRAW_STROKE) compute_stroke(sc, bins, es[k], grid, r, bounds, sd, arg);
        else compute_entry(sc, bins, tile, es[k], grid, r, args, sd, arg);
    }
}

// A long stroke entry: stroke_sdf at each sample, as entry_sdf measures it, over the
// items of the sample's cell (CELL x CELL pixels) with their bounds (StrokeBound): the same
// distances and args, the same items measured in the same order, less those that could
// not have lowered the distance so far. A cell lists the items whose box, grown by r
// (LocalItems::may_reach's test at its widest reach), holds some sample of the cell: a
// sample scans about a quarter of the tile's list (19,000 pieces on issue 41's path), and
// the cell's items and bounds stay at hand from sample to sample.
void TileFields::compute_stroke(const SceneView& sc, const TileView& bins, const TileEntry& e, const SampleGrid& g,
                                double r, const StrokeBound* bounds, double* sd, SdfArg* arg) {
    constexpr int CELL = 2;
    const PreparedDraw& d = sc.draws[e.draw];
    const int rows = (int)g.row_y.size(), cols = (int)g.col_x.size();
    const int ncx = (g.x1 - g.x0 + CELL - 1) / CELL, ncy = (g.y1 - g.y0 + CELL - 1) / CELL, cells = ncx * ncy;
    // each cell column's (row's) samples' extent
    cell_x0_.assign(ncx, INFINITY);
    cell_x1_.assign(ncx, -INFINITY);
    cell_y0_.assign(ncy, INFINITY);
    cell_y1_.assign(ncy, -INFINITY);
    for (int col = 0; col < cols; ++col) {
        const int c = (g.col_pixel[col] - g.x0) / CELL;
        cell_x0_[c] = vmin(cell_x0_[c], g.col_x[col]);
        cell_x1_[c] = vmax(cell_x1_[c], g.col_x[col]);
    }
    for (int row = 0; row < rows; ++row) {
        const int c = (g.row_pixel[row] - g.y0) / CELL;
        cell_y0_[c] = vmin(cell_y0_[c], g.row_y[row]);
        cell_y1_[c] = vmax(cell_y1_[c], g.row_y[row]);
    }
    // The items any sample may reach, and the cells each reaches (counted, then listed).
    const LocalItem* li = bins.items.data() + e.first;
    const StrokeBound* draw_bounds = bounds + d.first_item;
    stroke_items_.clear();
    stroke_bounds_.clear();
    item_cells_.clear();  // per kept item: its cells' ranges, x0 x1 y0 y1
    cell_start_.assign(cells + 1, 0);
    for (int i = 0; i < e.count; ++i) {
        const LocalItem& l = li[i];
        // the cells some sample of which passes may_reach at reach r (the extents rise
        // with the cell: a range; a sample outside them fails it at any reach <= r)
        int a = 0, b = ncx - 1, c0 = 0, c1 = ncy - 1;
        while (a <= b && cell_x1_[a] < l.x0 - r) ++a;
        while (b >= a && cell_x0_[b] > l.x1 + r) --b;
        while (c0 <= c1 && cell_y1_[c0] < l.y0 - r) ++c0;
        while (c1 >= c0 && cell_y0_[c1] > l.y1 + r) --c1;
        if (a > b || c0 > c1) continue;
        stroke_items_.push_back({l.x0, l.y0, l.x1, l.y1, l.item});
        item_cells_.insert(item_cells_.end(), {a, b, c0, c1});
        for (int cy = c0; cy <= c1; ++cy)
            for (int cx = a; cx <= b; ++cx) ++cell_start_[cy * ncx + cx + 1];
    }
    const int kept = (int)stroke_items_.size();
    stroke_bounds_.resize(kept);
    for (int k = 0; k < kept; ++k) {
        if (k + 8 < kept) __builtin_prefetch(&draw_bounds[stroke_items_[k + 8].item]);  // (scattered)
        stroke_bounds_[k] = draw_bounds[stroke_items_[k].item];
    }
    for (int c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
    cell_index_.resize(cell_start_[cells]);
    for (int k = 0; k < kept; ++k) {  // (in the entry's order within each cell)
        const int* rg = item_cells_.data() + 4 * k;
        for (int cy = rg[2]; cy <= rg[3]; ++cy)
            for (int cx = rg[0]; cx <= rg[1]; ++cx) cell_index_[cell_start_[cy * ncx + cx]++] = k;
    }
    for (int c = cells; c > 0; --c) cell_start_[c] = cell_start_[c - 1];
    cell_start_[0] = 0;
    for (int row = 0; row < rows; ++row) {
        const int cy = (g.row_pixel[row] - g.y0) / CELL;
        for (int col = 0; col < cols; ++col) {
            const int c = cy * ncx + (g.col_pixel[col] - g.x0) / CELL;
            const CellItems items{cell_index_.data() + cell_start_[c], cell_start_[c + 1] - cell_start_[c],
                                  stroke_items_.data(), stroke_bounds_.data()};
            const int s = g.at(row, col);
            sd[s] = stroke_sdf(sc, d, items, {g.col_x[col], g.row_y[row]}, r, arg ? arg + s : nullptr);
        }
    }
}

FieldView TileFields::view() const {
    FieldView v;
    if (slots_ == 0) return v;
    v.slot = slot_.data();
    v.sd = sd_.data();
    v.arg = args_ ? arg_.data() : nullptr;
    v.n = n_;
    v.tile = tile_;
    return v;
}

// One pass over the entry's segments, each y-monotone sub-piece (PreparedSegment::sub_y)
// cut into capsules: chords of the curve with how far it strays from them (a curve's
// distance from its chord over dt of its parameter is at most dt^2 / 8 max |B''|). Into
// pieces_: the capsules within r of the samples, for the distances. Into row_add_ and
// leg_: the winding numbers' crossings, along tile_winding's path (e.winding, the vertical
// leg's crossings at or above a row, then each crossing of a sample's row between the
// sample and the region's right edge): a row crossing a sub-piece meets it in one
// capsule, whose x range (or, finer, its chord's x at the row, give or take the capsule's
// width) usually holds no sample; only where one does is the crossing solved for.
void TileFields::scan(const SceneView& sc, const TileView& bins, int tile, const TileEntry& e, const SampleGrid& g,
                      double r) {
    const Box region = bins.region(tile);
    const double x_max = region.x1;
    const int rows = (int)g.row_y.size(), cols = (int)g.col_x.size();
    const Box area{g.col_x.front(), g.row_y.front(), g.col_x.back(), g.row_y.back()};
    const double r2 = r * r;
    const double scale = 1 + std::fabs(area.x0) + std::fabs(area.x1) + std::fabs(area.y0) + std::fabs(area.y1);
    row_add_.assign(rows + 1, 0);
    leg_.assign((size_t)rows * (cols + 1), 0);
    pieces_.clear();
    const PreparedDraw& d = sc.draws[e.draw];
    const PreparedSegment* segs = sc.fill_items.data() + d.first_item;
    const LocalItem* items = bins.items.data() + e.first;
    // The samples of a row left of x = T cross the segment there (direction dir).
    auto cross = [&](int row, double T, int dir) {
        int n_left = g.first_col(T);
        if (n_left == 0) return;
        int* leg = leg_.data() + (size_t)row * (cols + 1);
        leg[0] += dir;
        leg[n_left] -= dir;
    };
    // A capsule from a to b (h wide), if it comes within r of the samples, relative to
    // origin_ in floats: h grows by what the floats may be off (a few of their ulps).
    origin_ = {area.x0, area.y0};
    auto push_piece = [&](int li, Vec2 a, Vec2 b, double h) {
        Box box;
        expand(box, a);
        expand(box, b);
        if (box_distance2(grown(box, h), area) >= r2) return;
        Piece pc;
        pc.li = li;
        a = a - origin_;
        b = b - origin_;
        pc.a[0] = (float)a.x;
        pc.a[1] = (float)a.y;
        pc.v[0] = (float)(b.x - a.x);
        pc.v[1] = (float)(b.y - a.y);
        double vx = pc.v[0], vy = pc.v[1], l2 = vx * vx + vy * vy;
        pc.inv2 = l2 > 0 ? (float)(1 / l2) : 0.0f;
        double big = 1 + vmax(vmax(std::fabs(a.x), std::fabs(a.y)), vmax(std::fabs(b.x), std::fabs(b.y)));
        pc.h = float_above(h + 8 * FLT_EPSILON * big);
        pieces_.push_back(pc);
    };
    // A line's part within r + 1 of the samples (the rest is farther than r from each).
    const Box clip_box = grown(area, r + 1);
    auto push_line = [&](int li, Vec2 a, Vec2 b) {
        double t0 = 0, t1 = 1;
        const double dx = b.x - a.x, dy = b.y - a.y;
        auto clip = [&](double p, double q) {  // p t <= q
            if (p == 0) return q >= 0;
            double t = q / p;
            if (p < 0) t0 = vmax(t0, t);
            else t1 = vmin(t1, t);
            return t0 <= t1;
        };
        if (!(clip(-dx, a.x - clip_box.x0) && clip(dx, clip_box.x1 - a.x) && clip(-dy, a.y - clip_box.y0) &&
              clip(dy, clip_box.y1 - a.y)))
            return;
        push_piece(li, t0 > 0 ? a + t0 * (b - a) : a, t1 < 1 ? a + t1 * (b - a) : b, 0.0);
    };
    Vec2 pts[MAX_CAPSULES + 1];
    for (int li = 0; li < e.count; ++li) {
        if (li + 8 < e.count) __builtin_prefetch(&segs[items[li + 8].item].box);  // (a tile's segments are scattered)
        const LocalItem& item = items[li];
        if (item.cross >= 0) {
            const LegCrossings& c = bins.crossings[item.cross];
            for (int k = 0; k < c.n; ++k) row_add_[g.first_row(c.y[k])] += c.dir[k];
        }
        // (winding: some sample row within its heights has samples left of it, within the
        // region; distance: within r of the samples)
        if (item.y1 < area.y0 - r || item.y0 > area.y1 + r) continue;
        const PreparedSegment& s = segs[item.item];
        const bool wind = s.box.x0 <= x_max && s.box.x1 > area.x0 && s.box.y1 >= area.y0 && s.box.y0 <= area.y1;
        if (!wind && box_distance2(s.box, area) >= r2) continue;
        double ax[4], ay[4];
        s.power_basis(ax, ay);
        for (int k = 0; k + 1 < s.n_split; ++k) {
            const double ya = s.split_y[k], yb = s.split_y[k + 1];
            const int dir = ya < yb ? 1 : -1;
            double sy[PreparedSegment::SUB + 1];
            for (int j = 0; j <= s.n_sub; ++j) sy[j] = s.sub_y(k, j);
            bool monotone = true;  // the cuts, to rounding (else ray_crossings takes the whole piece)
            for (int j = 0; j < s.n_sub; ++j) monotone &= dir > 0 ? sy[j] <= sy[j + 1] : sy[j] >= sy[j + 1];
            if (!monotone) {  // rare: each row's crossing solved on the whole piece
                if (ya == yb || s.piece_x0[k] > x_max) continue;
                for (int row = g.first_row(vmin(ya, yb)); row < g.first_row(vmax(ya, yb)); ++row) {
                    const double y = g.row_y[row];
                    double t = monotone_root(ay, y, s.split[k], s.split[k + 1], ya - y, yb - y);
                    double x = ((ax[3] * t + ax[2]) * t + ax[1]) * t + ax[0];
                    if (x <= x_max) cross(row, x, dir);
                }
            }
            for (int j = 0; j < s.n_sub; ++j) {
                const double y0 = sy[j], y1 = sy[j + 1], ta = s.sub_t(k, j), tb = s.sub_t(k, j + 1);
                const Box sub{s.sub_x0[k][j], vmin(y0, y1), s.sub_x1[k][j], vmax(y0, y1)};
                const bool near = box_distance2(sub, area) < r2;
                // rows on the sub-piece's half-open range of heights, as ray_crossings picks it
                const int r_lo = monotone ? g.first_row(sub.y0) : 0, r_hi = monotone ? g.first_row(sub.y1) : 0;
                const bool rows_here = r_lo < r_hi && sub.x0 <= x_max && sub.x1 > area.x0;
                if (!near && !rows_here) continue;
                // capsules: chords at even steps of t, and how far the curve strays from them
                const double len = (sub.x1 - sub.x0) + (sub.y1 - sub.y0);
                const int n = s.seg.degree == 1 ? 1 : clamp_to_int(std::ceil(len / PIECE), 1, MAX_CAPSULES);
                const double slack = 1e-12 * (scale + std::fabs(sub.x0) + std::fabs(sub.x1) + std::fabs(sub.y0) +
                                              std::fabs(sub.y1));
                const double h = sub_piece_capsules(s, ax, ay, k, j, n, pts) + slack;
                if (near) {
                    if (s.seg.degree == 1) push_line(li, pts[0], pts[1]);
                    else for (int i = 0; i < n; ++i) push_piece(li, pts[i], pts[i + 1], h);
                }
                if (!rows_here) continue;
                int i = dir > 0 ? 0 : n - 1;  // the capsule at the row's height (rows go up in y)
                for (int row = r_lo; row < r_hi; ++row) {
                    const double y = g.row_y[row];
                    if (dir > 0) while (i + 1 < n && pts[i + 1].y <= y) ++i;
                    else while (i > 0 && pts[i].y <= y) --i;
                    const Vec2 a = pts[i], b = pts[i + 1];
                    double T = 0;
                    bool known = false;
                    const double lo_y = vmin(a.y, b.y), hi_y = vmax(a.y, b.y);
                    if (lo_y <= y && y < hi_y && y - lo_y > slack && hi_y - y > slack) {  // (else: solve)
                        const double xl = vmin(a.x, b.x) - h, xh = vmax(a.x, b.x) + h;
                        if (xl > x_max) continue;
                        if (xh <= x_max && g.first_col(xl) == g.first_col(xh)) {
                            T = xl;
                            known = true;
                        } else {  // the chord's x at y, give or take the capsule's width across it
                            double ex = (y - a.y) / (b.y - a.y) * (b.x - a.x) + a.x;
                            double err = h * length(b - a) / (hi_y - lo_y) + slack;
                            if (ex - err > x_max) continue;
                            if (ex + err <= x_max && g.first_col(ex - err) == g.first_col(ex + err)) {
                                T = ex - err;
                                known = true;
                            }
                        }
                    }
                    if (!known) {
                        double t = monotone_root(ay, y, ta, tb, y0 - y, y1 - y);
                        double x = ((ax[3] * t + ax[2]) * t + ax[1]) * t + ax[0];
                        if (x > x_max) continue;
                        T = x;
                    }
                    cross(row, T, dir);
                }
            }
        }
    }
    winding_.assign(n_, 0);
    int w_row = e.winding;
    for (int row = 0; row < rows; ++row) {
        w_row += row_add_[row];
        const int* leg = leg_.data() + (size_t)row * (cols + 1);
        int acc = 0;
        for (int col = 0; col < cols; ++col) {
            acc += leg[col];
            winding_[g.at(row, col)] = w_row + acc;
        }
    }
}

void TileFields::compute_entry(const SceneView& sc, const TileView& bins, int tile, const TileEntry& e,
                               const SampleGrid& g, double r, bool args, double* sd, SdfArg* arg) {
    scan(sc, bins, tile, e, g, r);
    const PreparedDraw& d = sc.draws[e.draw];
    const LocalItem* items = bins.items.data() + e.first;
    // A piece's bound at p: the distance to its chord (relative to origin_), squared, before
    // its width h is taken off (a lower bound of the distance to its part of the curve).
    auto bound2 = [&](const Piece& pc, Vec2 p) {
        double qx = p.x - origin_.x - pc.a[0], qy = p.y - origin_.y - pc.a[1];
        double t = vclamp((qx * pc.v[0] + qy * pc.v[1]) * pc.inv2, 0.0, 1.0);
        double wx = qx - t * pc.v[0], wy = qy - t * pc.v[1];
        return wx * wx + wy * wy;
    };
    // The samples within `reach` of a piece (its chord's box grown by h).
    auto near = [&](const Piece& pc, double reach, auto visit) {
        double x0 = origin_.x + pc.a[0], x1 = x0 + pc.v[0], y0 = origin_.y + pc.a[1], y1 = y0 + pc.v[1];
        reach += pc.h;
        const int r0 = g.first_row(vmin(y0, y1) - reach), r1 = g.after_row(vmax(y0, y1) + reach);
        const int c0 = g.first_col(vmin(x0, x1) - reach), c1 = g.after_col(vmax(x0, x1) + reach);
        for (int row = r0; row < r1; ++row) {
            const int* index = g.index.data() + (size_t)row * g.col_x.size();
            for (int col = c0; col < c1; ++col) visit(index[col], Vec2{g.col_x[col], g.row_y[row]});
        }
    };
    // 1. Each sample's nearest bound, and its segment's distance d*.
    bound_.assign(n_, r);
    nearest_.assign(n_, -1);
    for (const Piece& pc : pieces_)
        near(pc, r, [&](int s, Vec2 p) {
            double lim = bound_[s] + pc.h, b2 = bound2(pc, p);
            if (b2 < lim * lim) {
                bound_[s] = std::sqrt(b2) - pc.h;
                nearest_[s] = pc.li;
            }
        });
    dstar_.resize(n_);
    for (int row = 0; row < (int)g.row_y.size(); ++row)
        for (int col = 0; col < (int)g.col_x.size(); ++col) {
            int s = g.at(row, col);
            double best = r;
            if (nearest_[s] >= 0) fill_distance_step(sc, d, items[nearest_[s]].item, {g.col_x[col], g.row_y[row]}, best, nullptr);
            dstar_[s] = best;
        }
    // 2. In the entry's order, the segments that may come within d* (or ON_EDGE, where the
    // args must find a second segment on a vertex), each measured once per sample.
    best_.assign(n_, r);
    stamp_.assign(n_, -1);
    double reach = 0;  // (the samples' limits are small where segments crowd, and so the reach)
    for (int s = 0; s < n_; ++s) reach = vmax(reach, args ? vmax(dstar_[s], ON_EDGE) : dstar_[s]);
    for (const Piece& pc : pieces_)
        near(pc, reach, [&](int s, Vec2 p) {
            if (stamp_[s] == pc.li) return;
            double limit = (args ? vmax(dstar_[s], ON_EDGE) : dstar_[s]) + pc.h;
            if (bound2(pc, p) > limit * limit) return;
            stamp_[s] = pc.li;
            fill_distance_step(sc, d, items[pc.li].item, p, best_[s], args ? arg + s : nullptr);
        });
    for (int s = 0; s < n_; ++s) sd[s] = winding_inside(winding_[s], d.fill_rule) ? -best_[s] : best_[s];
}

}  // namespace vf
