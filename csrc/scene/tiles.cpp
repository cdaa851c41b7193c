// Tile binning (tiles.h): which draws and which of their pieces reach each tile.
#include "scene/tiles.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "common/float_bounds.h"
#include "common/thread_pool.h"
#include "scene/coverage.h"
#include "scene/draw_runs.h"

namespace vf {
namespace {


struct TileRange {
    int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    bool empty() const { return x1 < x0 || y1 < y0; }
    int width() const { return x1 - x0 + 1; }
};

// Tiles whose region (tile grown by margin) overlaps the box, clipped to `clip`.
TileRange tiles_of(const Box& b, double margin, const TileRange& clip) {
    TileRange r;
    if (!valid(b)) return r;
    double x0 = std::floor((b.x0 - margin) / TILE), x1 = std::floor((b.x1 + margin) / TILE);
    double y0 = std::floor((b.y0 - margin) / TILE), y1 = std::floor((b.y1 + margin) / TILE);
    // (clamped as doubles: a box may lie 1e30 pixels away)
    r.x0 = clamp_to_int(x0, clip.x0, clip.x1 + 1);
    r.y0 = clamp_to_int(y0, clip.y0, clip.y1 + 1);
    r.x1 = clamp_to_int(x1, clip.x0 - 1, clip.x1);
    r.y1 = clamp_to_int(y1, clip.y0 - 1, clip.y1);
    return r;
}

// Crossings of the vertical line x = X, for heights in (y_low, y_high]: x-monotone
// pieces count on [x_low, x_high); direction +1 where the curve moves towards +x.
int vertical_crossings(const PreparedSegment& ps, double X, double y_low, double y_high, double* ys, int8_t* dirs) {
    const Segment& s = ps.seg;
    double ts[4] = {0, 0, 0, 0};
    double ext[2];
    int n_ext = seg_extrema(s, 0, ext);
    int n = 0;
    ts[n++] = 0;
    for (int i = 0; i < n_ext; ++i)
        if (ext[i] > ts[n - 1]) ts[n++] = ext[i];
    ts[n++] = 1;
    int count = 0;
    for (int k = 0; k + 1 < n; ++k) {
        double xa = seg_eval(s, ts[k]).x, xb = seg_eval(s, ts[k + 1]).x;
        int dir;
        if (xa <= X && X < xb) dir = 1;
        else if (xb <= X && X < xa) dir = -1;
        else continue;
        double ax[4], ay[4];
        ps.power_basis(ax, ay);
        double t = monotone_root(ax, X, ts[k], ts[k + 1], xa - X, xb - X);
        double y = ((ay[3] * t + ay[2]) * t + ay[1]) * t + ay[0];
        if (y > y_low && y <= y_high && count < 3) {
            ys[count] = y;
            dirs[count] = (int8_t)dir;
            ++count;
        }
    }
    return count;
}

struct Pending {
    int tile;
    TileEntry entry;
};

// Whether the tile's region lies inside one piece of a uniform-width stroke item: its
// sweep, when the item is a line (a rectangle in stroke space), or a round join or cap (a
// disk). The region maps to a parallelogram in stroke space, inside a convex piece when
// its four corners are.
bool region_inside_piece(const PreparedDraw& d, const StrokeSegment& s, const Box& region) {
    Vec2 corners[4] = {{region.x0, region.y0}, {region.x1, region.y0}, {region.x0, region.y1}, {region.x1, region.y1}};
    for (Vec2& c : corners) c = to_stroke_space(d, c);
    auto all = [&](auto inside) {
        for (const Vec2& c : corners)
            if (!inside(c)) return false;
        return true;
    };
    const double hw = d.half_width;
    for (const StrokeEnd* e : {&s.start, &s.end})
        if (e->kind == StrokeEnd::DISK && all([&](Vec2 q) { return distance(q, e->center) <= e->hw; })) return true;
    if (s.seg.degree != 1) return false;
    Vec2 a = s.seg.p[0], u = s.seg.p[1] - a;
    double len = length(u);
    if (!(len > 0)) return false;
    u = (1 / len) * u;
    return all([&](Vec2 q) {
        double along = dot(q - a, u);
        return along >= 0 && along <= len && std::fabs(cross(u, q - a)) <= hw;
    });
}

// A worker's buffers for bin_path_draw, reused from draw to draw.
struct DrawScratch {
    std::vector<int> counts, start, local, cursor;
    std::vector<char> full;
    std::vector<int> stamp;
    std::vector<TileRange> item_tiles;
    std::vector<std::array<float, 4>> stroke_boxes;
    std::vector<std::vector<std::pair<double, int>>> row_crossings;
};

// Bins the items of one path draw into its tiles (counting sort within its tile range)
// and emits an entry per tile that the draw can affect.
void bin_path_draw(const PreparedScene& sc, const PreparedDraw& d, int draw_index, const TileRange& range,
                   const TileBins& bins, bool every_tile, std::vector<Pending>& pending,
                   std::vector<LocalItem>& items, std::vector<LegCrossings>& crossings, DrawScratch& scratch) {
    const bool fill = d.kind == DRAW_FILL;
    const int w = range.width(), h = range.y1 - range.y0 + 1;
    auto item_box = [&](int k) -> const Box& {
        return fill ? sc.fill_items[d.first_item + k].box : sc.stroke_items[d.first_item + k].box;
    };
    std::vector<int>& counts = scratch.counts;
    counts.assign(w * h + 1, 0);
    std::vector<TileRange>& item_tiles = scratch.item_tiles;
    item_tiles.resize(d.n_items);
    for (int k = 0; k < d.n_items; ++k) item_tiles[k] = tiles_of(item_box(k), bins.margin, range);
    // Strokes wide against a tile: the tiles inside one of their pieces are covered there,
    // whatever the other items do; they list no items (a stroke 10^7 px wide listed every
    // item in every tile: gigabytes, and the analytical mode measured each one per pixel).
    std::vector<char>& full = scratch.full;
    full.assign(w * h, 0);
    int n_full = 0;
    if (!fill && !d.varying && d.half_width * d.metric_scale >= 0.5 * TILE + bins.margin) {
        for (int k = 0; k < d.n_items && n_full < w * h; ++k) {
            const StrokeSegment& s = sc.stroke_items[d.first_item + k];
            if (s.seg.degree != 1 && s.start.kind != StrokeEnd::DISK && s.end.kind != StrokeEnd::DISK) continue;
            const TileRange& r = item_tiles[k];
            for (int ty = r.y0; ty <= r.y1; ++ty)
                for (int tx = r.x0; tx <= r.x1; ++tx) {
                    int cell = (ty - range.y0) * w + (tx - range.x0);
                    if (!full[cell] && region_inside_piece(d, s, bins.region(ty * bins.nx + tx))) {
                        full[cell] = 1;
                        ++n_full;
                    }
                }
        }
    }
    // The tiles an item is listed in: those its box reaches, but for a curve of a fill only
    // those its capsules reach (sub_piece_capsules: chords about half a tile long grown by
    // how far the curve strays from them; a curve across the canvas was listed in every
    // tile of its box, then in the fifty of its sub-pieces' boxes, and passes through a
    // dozen). A curve that reaches no part of a region crosses neither leg of the winding
    // path there (the corner rays count every segment, see above).
    std::vector<int>& stamp = scratch.stamp;
    stamp.assign(w * h, -1);
    auto for_each_tile = [&](int k, auto visit) {
        const TileRange& r = item_tiles[k];
        const PreparedSegment* seg = fill ? &sc.fill_items[d.first_item + k] : nullptr;
        if (!seg || seg->seg.degree == 1 || r.width() * (r.y1 - r.y0 + 1) <= 4) {
            for (int ty = r.y0; ty <= r.y1; ++ty)
                for (int tx = r.x0; tx <= r.x1; ++tx) visit((ty - range.y0) * w + (tx - range.x0));
            return;
        }
        auto visit_range = [&](const TileRange& sr) {
            for (int ty = sr.y0; ty <= sr.y1; ++ty)
                for (int tx = sr.x0; tx <= sr.x1; ++tx) {
                    int cell = (ty - range.y0) * w + (tx - range.x0);
                    if (stamp[cell] != k) {
                        stamp[cell] = k;
                        visit(cell);
                    }
                }
        };
        double ax[4], ay[4];
        seg->power_basis(ax, ay);
        Vec2 pts[65];
        for (int i = 0; i + 1 < seg->n_split; ++i)
            for (int j = 0; j < seg->n_sub; ++j) {
                double ya = seg->sub_y(i, j), yb = seg->sub_y(i, j + 1);
                Box sub{seg->sub_x0[i][j], std::min(ya, yb), seg->sub_x1[i][j], std::max(ya, yb)};
                TileRange sr = tiles_of(sub, bins.margin, r);
                if (sr.empty()) continue;
                if (sr.width() * (sr.y1 - sr.y0 + 1) <= 2) {
                    visit_range(sr);
                    continue;
                }
                // A sub-piece's box can hold many tiles its curve never comes near (a curve
                // across the canvas): capsules of about half a tile.
                int n = clamp_to_int(std::ceil(((sub.x1 - sub.x0) + (sub.y1 - sub.y0)) / (0.5 * TILE)), 1, 64);
                double h = sub_piece_capsules(*seg, ax, ay, i, j, n, pts);
                for (int c = 0; c < n; ++c) {
                    Box b;
                    expand(b, pts[c]);
                    expand(b, pts[c + 1]);
                    visit_range(tiles_of(grown(b, h), bins.margin, sr));
                }
            }
    };
    for (int k = 0; k < d.n_items; ++k)
        for_each_tile(k, [&](int cell) { counts[cell] += !full[cell]; });
    std::vector<int>& start = scratch.start;
    start.assign(w * h + 1, 0);
    for (int i = 0; i < w * h; ++i) start[i + 1] = start[i] + counts[i];
    std::vector<int>& local = scratch.local;
    local.resize(start[w * h]);
    std::vector<int>& cursor = scratch.cursor;
    cursor.assign(start.begin(), start.end() - 1);
    stamp.assign(w * h, -1);
    for (int k = 0; k < d.n_items; ++k)
        for_each_tile(k, [&](int cell) {
            if (!full[cell]) local[cursor[cell]++] = k;
        });

    // Fills: crossings of each tile row's top line, to count the corner rays.
    std::vector<std::vector<std::pair<double, int>>>& row_crossings = scratch.row_crossings;
    if (fill) {
        if ((int)row_crossings.size() < h) row_crossings.resize(h);
        for (int r = 0; r < h; ++r) row_crossings[r].clear();
        for (int k = 0; k < d.n_items; ++k) {
            const PreparedSegment& s = sc.fill_items[d.first_item + k];
            double ax[4], ay[4];
            s.power_basis(ax, ay);
            int r0 = clamp_to_int(std::ceil((s.box.y0 + bins.margin) / TILE), range.y0, range.y1 + 1);
            int r1 = clamp_to_int(std::floor((s.box.y1 + bins.margin) / TILE), range.y0 - 1, range.y1);
            for (int ty = r0; ty <= r1; ++ty) {
                double y = ty * (double)TILE - bins.margin;
                for (int j = 0; j + 1 < s.n_split; ++j) {
                    double ya = s.split_y[j], yb = s.split_y[j + 1];
                    int dir;
                    if (ya <= y && y < yb) dir = 1;
                    else if (yb <= y && y < ya) dir = -1;
                    else continue;
                    double t = monotone_root(ay, y, s.split[j], s.split[j + 1], ya - y, yb - y);
                    double x = ((ax[3] * t + ax[2]) * t + ax[1]) * t + ax[0];
                    row_crossings[ty - range.y0].push_back({x, dir});
                }
            }
        }
    }

    // Strokes: each piece's box as floats, once (the pieces are 384 bytes each and a long
    // path's are listed in many tiles: read per listing, they slowed the binning, which
    // runs one draw on one thread).
    if (!fill) {
        scratch.stroke_boxes.resize(d.n_items);
        for (int k = 0; k < d.n_items; ++k) {
            const Box& b = sc.stroke_items[d.first_item + k].box;
            scratch.stroke_boxes[k] = {float_below(b.x0), float_below(b.y0), float_above(b.x1), float_above(b.y1)};
        }
    }
    // (room for the draw's items at once: one long path's are most of the bins)
    const size_t needed = items.size() + (size_t)start[w * h];
    if (needed > items.capacity()) items.reserve(std::max(needed, 2 * items.capacity()));
    for (int ty = range.y0; ty <= range.y1; ++ty) {
        std::vector<std::pair<double, int>>* row = fill ? &row_crossings[ty - range.y0] : nullptr;
        if (row) std::sort(row->begin(), row->end());
        // Sweep the row from the right: winding of the corner ray of each tile.
        int winding = 0;
        int next = row ? (int)row->size() - 1 : -1;
        for (int tx = range.x1; tx >= range.x0; --tx) {
            int tile = ty * bins.nx + tx;
            Box region = bins.region(tile);
            if (row) {
                while (next >= 0 && (*row)[next].first > region.x1) winding += (*row)[next--].second;
            }
            int cell = (ty - range.y0) * w + (tx - range.x0);
            int n_local = start[cell + 1] - start[cell];
            if (n_local == 0 && !every_tile && !full[cell] && !(fill && winding_inside(winding, d.fill_rule)))
                continue;
            TileEntry e;
            e.draw = draw_index;
            e.winding = fill ? winding : full[cell];
            e.first = (int)items.size();
            e.count = n_local;
            for (int i = start[cell]; i < start[cell + 1]; ++i) {
                LocalItem li;
                li.item = local[i];
                if (fill) {
                    const PreparedSegment& s = sc.fill_items[d.first_item + li.item];
                    li.y0 = float_below(s.box.y0);
                    li.y1 = float_above(s.box.y1);
                    LegCrossings c;
                    if (s.box.x0 <= region.x1 && region.x1 <= s.box.x1)
                        c.n = (int8_t)vertical_crossings(s, region.x1, region.y0, region.y1, c.y, c.dir);
                    if (c.n > 0) {
                        li.cross = (int)crossings.size();
                        crossings.push_back(c);
                    }
                }
                else {  // strokes: the piece's box, read per sample without the piece itself
                    const std::array<float, 4>& b = scratch.stroke_boxes[li.item];
                    li.x0 = b[0];
                    li.y0 = b[1];
                    li.x1 = b[2];
                    li.y1 = b[3];
                }
                items.push_back(li);
            }
            pending.push_back({tile, e});
        }
    }
}

// The entries and items of a run of consecutive draws, their `first` counted from the
// run's own items.
struct DrawRun {
    int begin = 0, end = 0;
    std::vector<Pending> pending;
    std::vector<LocalItem> items;
    std::vector<LegCrossings> crossings;
};

void bin_run(const PreparedScene& sc, const TileBins& bins, const TileRange& all, bool every_tile, DrawRun& run,
             DrawScratch& scratch) {
    for (int i = run.begin; i < run.end; ++i) {
        const PreparedDraw& d = sc.draws[i];
        TileRange range = tiles_of(d.box, bins.margin, all);
        if (range.empty()) continue;
        if (d.is_ellipse) {
            for (int ty = range.y0; ty <= range.y1; ++ty)
                for (int tx = range.x0; tx <= range.x1; ++tx) run.pending.push_back({ty * bins.nx + tx, TileEntry{i, 0, 0, 0}});
        } else {
            bin_path_draw(sc, d, i, range, bins, every_tile, run.pending, run.items, run.crossings, scratch);
        }
    }
}

}  // namespace

TileBins bin_draws(const PreparedScene& sc, int width, int height, double margin, bool every_tile, int threads) {
    TileBins bins;
    bins.nx = (width + TILE - 1) / TILE;
    bins.ny = (height + TILE - 1) / TILE;
    bins.margin = margin;
    TileRange all{0, 0, bins.nx - 1, bins.ny - 1};
    // Draws are binned independently, in runs shared out between threads (see draw_runs).
    const int n_draws = (int)sc.draws.size();
    threads = draw_threads(threads, n_draws);
    const std::vector<int> bounds = draw_runs(sc.draws.data(), n_draws, threads);
    const int n_runs = (int)bounds.size() - 1;
    std::vector<DrawRun> runs(n_runs);
    for (int r = 0; r < n_runs; ++r) {
        runs[r].begin = bounds[r];
        runs[r].end = bounds[r + 1];
    }
    std::vector<DrawScratch> scratch(threads);
    ThreadPool::instance().parallel_for(n_runs, threads, [&](int r, int worker) {
        bin_run(sc, bins, all, every_tile, runs[r], scratch[worker]);
    });

    // The runs joined: their items in order, and a stable counting sort of their entries
    // by tile (which keeps each tile's entries in paint order), the two side by side.
    std::vector<size_t> item_offset(n_runs + 1, 0), cross_offset(n_runs + 1, 0);
    for (int r = 0; r < n_runs; ++r) {
        item_offset[r + 1] = item_offset[r] + runs[r].items.size();
        cross_offset[r + 1] = cross_offset[r] + runs[r].crossings.size();
    }
    const int n_tiles = bins.nx * bins.ny;
    auto join_items = [&] {
        if (n_runs == 1) {  // (one run, the common case for one long path: no copies)
            bins.items = std::move(runs[0].items);
            bins.crossings = std::move(runs[0].crossings);
            return;
        }
        bins.items.resize(item_offset[n_runs]);
        bins.crossings.resize(cross_offset[n_runs]);
        for (int r = 0; r < n_runs; ++r) {
            LocalItem* out = bins.items.data() + item_offset[r];
            for (size_t i = 0; i < runs[r].items.size(); ++i) {
                out[i] = runs[r].items[i];
                if (out[i].cross >= 0) out[i].cross += (int)cross_offset[r];
            }
            std::vector<LocalItem>().swap(runs[r].items);
            std::copy(runs[r].crossings.begin(), runs[r].crossings.end(), bins.crossings.begin() + cross_offset[r]);
            std::vector<LegCrossings>().swap(runs[r].crossings);
        }
    };
    auto sort_entries = [&] {
        bins.start.assign(n_tiles + 1, 0);
        for (const DrawRun& run : runs)
            for (const Pending& p : run.pending) ++bins.start[p.tile + 1];
        for (int t = 0; t < n_tiles; ++t) bins.start[t + 1] += bins.start[t];
        bins.entries.resize(bins.start[n_tiles]);
        std::vector<int> cursor(bins.start.begin(), bins.start.end() - 1);
        for (int r = 0; r < n_runs; ++r)
            for (const Pending& p : runs[r].pending) {
                TileEntry& e = bins.entries[cursor[p.tile]++];
                e = p.entry;
                e.first += (int)item_offset[r];
            }
    };
    bool done[2] = {false, false};
    ThreadPool::instance().parallel_for(2, threads, [&](int task, int) {
        task == 0 ? join_items() : sort_entries();
        done[task] = true;
    });
    // (tasks skipped by a cancel: the bins stay whole, for whatever still reads them)
    if (!done[0]) join_items();
    if (!done[1]) sort_entries();
    return bins;
}

}  // namespace vf
