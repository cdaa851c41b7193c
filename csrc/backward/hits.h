// The draws at a point, front to back, as both terms of the backward pass see them: the
// Monte Carlo hits (a draw covers the point or not; one may be forced in) and the
// analytical prefilter's (fractional coverage, with where the signed distance came from).
#pragma once

#include <cmath>

#include "common/portable.h"
#include "forward/forward.h"
#include "scene/coverage.h"
#include "scene/paint.h"
#include "scene/scene.h"
#include "scene/tiles.h"

namespace vf {

struct Hit {
    int draw;
    double c[4];  // premultiplied colour of the draw at the point (times its coverage)
    // analytical prefilter only: coverage K(sd / r), the signed distance, the paint colour
    // (premultiplied) and the piece the distance came from
    double cov = 1, sd = 0, paint[4] = {0, 0, 0, 0};
    SdfArg arg;
};

VF_HD int tile_of(const TileView& bins, Vec2 p) {
    int tx = clamp_to_int(std::floor(p.x / TILE), 0, bins.nx - 1);
    int ty = clamp_to_int(std::floor(p.y / TILE), 0, bins.ny - 1);
    return ty * bins.nx + tx;
}

VF_HD bool covers(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region, Vec2 p) {
    const Box& b = sc.draws[e.draw].box;
    return p.x >= b.x0 && p.x <= b.x1 && p.y >= b.y0 && p.y <= b.y1 && entry_covers(sc, bins, e, region, p);
}

// Draw `draw`'s entry in tile `tile`, or null where the draw reaches nothing there.
VF_HD const TileEntry* entry_of(const TileView& bins, int tile, int draw) {
    const TileEntry* es = bins.begin(tile);
    int n = bins.count(tile);
    int lo = 0, hi = n;  // entries are sorted by draw index (paint order)
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (es[mid].draw < draw) lo = mid + 1; else hi = mid;
    }
    return lo < n && es[lo].draw == draw ? es + lo : nullptr;
}

// Does draw `draw` cover p? (p inside the tile grid's reach.)
VF_HD bool draw_covers_at(const SceneView& sc, const TileView& bins, int draw, Vec2 p) {
    int tile = tile_of(bins, p);
    Box region = bins.region(tile);
    if (p.x < region.x0 || p.x > region.x1 || p.y < region.y0 || p.y > region.y1) return false;
    const TileEntry* e = entry_of(bins, tile, draw);
    return e && covers(sc, bins, *e, region, p);
}

// Whether the entry's draw covers each of two points of the tile region: covers() for
// both, the crossings of both counted in one pass over a fill's segments.
VF_HD void covers_pair(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region, Vec2 a,
                       Vec2 b, bool& in_a, bool& in_b) {
    const PreparedDraw& d = sc.draws[e.draw];
    auto in_box = [&](Vec2 p) { return p.x >= d.box.x0 && p.x <= d.box.x1 && p.y >= d.box.y0 && p.y <= d.box.y1; };
    bool ra = in_box(a), rb = in_box(b);
    in_a = in_b = false;
    if (!ra && !rb) return;
    if (d.kind != DRAW_FILL || d.is_ellipse) {
        in_a = ra && entry_covers(sc, bins, e, region, a);
        in_b = rb && entry_covers(sc, bins, e, region, b);
        return;
    }
    const PreparedSegment* segs = sc.fill_items.data() + d.first_item;
    const LocalItem* items = bins.items.data() + e.first;
    int wa = e.winding, wb = e.winding;
    for (int i = 0; i < e.count; ++i) {
        const LocalItem& li = items[i];
        if (li.spans(a.y)) wa += ray_crossings(segs[li.item], a, region.x1);
        if (li.spans(b.y)) wb += ray_crossings(segs[li.item], b, region.x1);
        wa += bins.leg_crossings(li, a.y);
        wb += bins.leg_crossings(li, b.y);
    }
    in_a = ra && winding_inside(wa, d.fill_rule);
    in_b = rb && winding_inside(wb, d.fill_rule);
}

// Whether the entry's draw covers p, or has an edge of its own between p and `inside` (a
// point a hair away, both in the tile region) and covers `inside`. A fill's crossings are
// counted at p alone unless one of its segments' boxes meets the box of the two points:
// where none does, no segment passes between them and both have the same winding number.
VF_HD bool covers_or_edge_to(const SceneView& sc, const TileView& bins, const TileEntry& e, const Box& region,
                             Vec2 p, Vec2 inside) {
    const PreparedDraw& d = sc.draws[e.draw];
    auto in_box = [&](Vec2 q) { return q.x >= d.box.x0 && q.x <= d.box.x1 && q.y >= d.box.y0 && q.y <= d.box.y1; };
    const bool rp = in_box(p), ri = in_box(inside);
    if (!rp && !ri) return false;
    if (d.kind != DRAW_FILL || d.is_ellipse)
        return (rp && entry_covers(sc, bins, e, region, p)) || (ri && entry_covers(sc, bins, e, region, inside));
    const PreparedSegment* segs = sc.fill_items.data() + d.first_item;
    const LocalItem* items = bins.items.data() + e.first;
    const Box pair{vmin(p.x, inside.x), vmin(p.y, inside.y), vmax(p.x, inside.x), vmax(p.y, inside.y)};
    int w = e.winding;
    bool near = false;
    for (int i = 0; i < e.count; ++i) {
        const LocalItem& li = items[i];
        if (li.y0 <= pair.y1 && li.y1 >= pair.y0) {
            const PreparedSegment& s = segs[li.item];
            if (li.spans(p.y)) w += ray_crossings(s, p, region.x1);
            near = near || (s.box.x0 <= pair.x1 && s.box.x1 >= pair.x0 && s.box.y0 <= pair.y1 && s.box.y1 >= pair.y0);
        }
        w += bins.leg_crossings(li, p.y);
    }
    if (rp && winding_inside(w, d.fill_rule)) return true;
    return near && ri && winding_inside(tile_winding(sc, bins, e, region, inside), d.fill_rule);
}

// Whether draw `draw` covers each of two points a hair apart (either side of one of its
// boundaries): draw_covers_at for both, with the entry looked up once and the crossings of
// both points counted in one pass over its segments when they share a tile (fills).
VF_HD void draw_covers_pair(const SceneView& sc, const TileView& bins, int draw, Vec2 a, Vec2 b, bool& in_a,
                            bool& in_b) {
    int tile = tile_of(bins, a);
    if (tile != tile_of(bins, b)) {
        in_a = draw_covers_at(sc, bins, draw, a);
        in_b = draw_covers_at(sc, bins, draw, b);
        return;
    }
    in_a = in_b = false;
    Box region = bins.region(tile);
    auto reached = [&](Vec2 p) { return p.x >= region.x0 && p.x <= region.x1 && p.y >= region.y0 && p.y <= region.y1; };
    bool ra = reached(a), rb = reached(b);
    if (!ra && !rb) return;
    const TileEntry* e = entry_of(bins, tile, draw);
    if (!e) return;
    covers_pair(sc, bins, *e, region, a, b, in_a, in_b);
    in_a = in_a && ra;
    in_b = in_b && rb;
}

// Draws covering p, front to back, with their premultiplied colours; `forced` (if >= 0)
// counts as covering. With AT_EDGE, for a boundary sample's composites (see
// jump_without_layers): `edge_of` is the sampled draw and `inside` the point a hair inside
// it, and a draw behind it that covers `inside` but not p (its own edge through the sample,
// on the same side) counts as covering p too. Returns the count.
template <bool AT_EDGE>
VF_HD int collect_hits_of(const SceneView& sc, const TileView& bins, Vec2 p, int forced, Buffer<Hit>& hits,
                          int edge_of, Vec2 inside) {
    hits.clear();
    int tile = tile_of(bins, p);
    Box region = bins.region(tile);
    bool in_region = p.x >= region.x0 && p.x <= region.x1 && p.y >= region.y0 && p.y <= region.y1;
    const bool inside_in_region = AT_EDGE && inside.x >= region.x0 && inside.x <= region.x1 &&
                                  inside.y >= region.y0 && inside.y <= region.y1;
    const TileEntry* es = bins.begin(tile);
    int n = in_region ? bins.count(tile) : 0;
    bool forced_done = forced < 0;
    // Without layers, what lies behind a second opaque draw cannot matter: the first
    // opaque one hides it, and that one's alpha derivative needs only the composite behind
    // it, which the second one ends.
    bool may_stop = forced < 0 && sc.layer_parent.size() <= 1;
    int opaque = 0;
    auto add = [&](int draw) {
        Hit h;
        h.draw = draw;
        paint_color(sc, sc.paints[sc.draws[draw].paint], p, h.c);
        hits.push_back(h);
        if (h.c[3] >= 1) ++opaque;
    };
    for (int k = n - 1; k >= 0 && !(may_stop && opaque >= 2); --k) {
        int draw = es[k].draw;
        if (!forced_done && forced > draw) {
            add(forced);
            forced_done = true;
        }
        if (draw == forced) {
            add(forced);
            forced_done = true;
            continue;
        }
        if (AT_EDGE && inside_in_region && draw < edge_of) {
            if (covers_or_edge_to(sc, bins, es[k], region, p, inside)) add(draw);
            continue;
        }
        if (covers(sc, bins, es[k], region, p)) add(draw);
    }
    if (!forced_done) add(forced);
    return (int)hits.size();
}

VF_HD int collect_hits(const SceneView& sc, const TileView& bins, Vec2 p, int forced, Buffer<Hit>& hits) {
    return collect_hits_of<false>(sc, bins, p, forced, hits, -1, p);
}

// Analytical prefilter: the draws reaching p, front to back, with fractional coverage.
// fields: the signed distances of some entries at the tile's samples, p being sample
// `sample` of them (see FieldView), or null.
VF_HD void collect_hits_analytic(const SceneView& sc, const TileView& bins, Vec2 p, double r, Buffer<Hit>& hits,
                                 const FieldView* fields = nullptr, int sample = 0) {
    hits.clear();
    int tile = tile_of(bins, p);
    Box region = bins.region(tile);
    const TileEntry* es = bins.begin(tile);
    if (fields && fields->tile != tile) fields = nullptr;  // (a sample beyond its pixel's tile)
    // Without layers, what lies behind a second opaque hit cannot matter (see collect_hits).
    const bool may_stop = sc.layer_parent.size() <= 1;
    int opaque = 0;
    for (int k = bins.count(tile) - 1; k >= 0 && !(may_stop && opaque >= 2); --k) {
        const TileEntry& e = es[k];
        const PreparedDraw& d = sc.draws[e.draw];
        Box near = grown(d.box, r);
        if (p.x < near.x0 || p.x > near.x1 || p.y < near.y0 || p.y > near.y1) continue;
        Hit h;
        h.draw = e.draw;
        if (fields && fields->has(k)) {
            h.sd = fields->sd_at(k, sample);
            h.arg = fields->arg_at(k, sample);
        } else {
            h.sd = entry_sdf(sc, bins, e, region, p, r, &h.arg);
        }
        if (h.arg.kind == SdfArg::SEGMENT && std::fabs(h.sd) < ON_EDGE) {
            if (h.arg.item2 < 0) h.arg.side = entry_inside_side(sc, bins, e, region, h.arg);
            else {  // on a vertex: each segment's side, probed a little into the segment (at
                    // the vertex itself the probes lie on the other edge's line)
                for (int k = 0; k < 2; ++k) {
                    SdfArg a = h.arg;
                    a.item = k == 0 ? h.arg.item : h.arg.item2;
                    a.t = k == 0 ? h.arg.t : h.arg.t2;
                    const Segment& sg = sc.fill_items[a.item].seg;
                    Vec2 tangent = seg_deriv(sg, a.t);
                    double speed = length(tangent);
                    a.closest = seg_eval(sg, a.t);
                    if (speed > 0) a.closest = a.closest + ((a.t < 0.5 ? 100 : -100) * ON_EDGE / speed) * tangent;
                    (k == 0 ? h.arg.side : h.arg.side2) = (int8_t)entry_inside_side(sc, bins, e, region, a);
                }
            }
        }
        h.cov = kernel_coverage(h.sd / r);
        if (h.cov <= 0) continue;
        paint_color(sc, sc.paints[d.paint], p, h.paint);
        for (int i = 0; i < 4; ++i) h.c[i] = h.cov * h.paint[i];
        hits.push_back(h);
        if (h.c[3] >= 1) ++opaque;
    }
}

}  // namespace vf
