// Compositing in the backward pass: the hits at a point composited with a tape
// (composite_forward) and that tape run in reverse (composite_backward), with layers for
// group opacity; and, for the boundary term of scenes without layers, the jump of the
// composite when one draw comes to cover a point. composite_forward computes what the
// forward pass's FrontToBackCompositor (forward/composite.h) does, to rounding: that one
// streams the draws front to back and stops once a sample is opaque, this one needs the
// whole list and evaluates it back to front, which is what the tape records.
#pragma once

#include "backward/grads.h"
#include "backward/hits.h"
#include "common/portable.h"
#include "scene/layers.h"
#include "scene/paint.h"
#include "scene/scene.h"
#include "scene/tiles.h"

namespace vf {

// One step of composite_forward, with what composite_backward needs to undo it.
struct TapeOp {
    enum Kind { OVER, PUSH, POP } kind;
    int ref;           // hit index (OVER) or layer (PUSH/POP)
    double prev[4];    // the frame's colour before the op (OVER) / the parent's (POP)
    double layer[4];   // the closed layer's colour (POP)
};

struct Tape {
    using Op = TapeOp;
    static constexpr TapeOp::Kind OVER = TapeOp::OVER, PUSH = TapeOp::PUSH, POP = TapeOp::POP;
    Buffer<TapeOp> ops;
};

// dL/d(a hit's premultiplied colour).
struct Quad {
    double v[4];
    VF_HD double& operator[](int i) { return v[i]; }
    VF_HD double operator[](int i) const { return v[i]; }
};

// Compositing of hits (given front to back) evaluated back to front, recording the tape
// when one is given; out: the premultiplied result.
VF_HD void composite_forward(const SceneView& sc, const Buffer<Hit>& hits, Tape* tape, double out[4]) {
    LayerFrame stack[MAX_LAYER_DEPTH];
    int top = 0;
    stack[0].layer = 0;
    for (int i = 0; i < 4; ++i) stack[0].c[i] = 0;
    if (tape) tape->ops.clear();
    auto pop = [&] {
        LayerFrame& child = stack[top];
        LayerFrame& parent = stack[top - 1];
        double op = sc.layer_opacity[child.layer];
        if (tape) {
            Tape::Op o{Tape::POP, child.layer, {}, {}};
            for (int i = 0; i < 4; ++i) { o.prev[i] = parent.c[i]; o.layer[i] = child.c[i]; }
            tape->ops.push_back(o);
        }
        double k = 1 - op * child.c[3];
        for (int i = 0; i < 4; ++i) parent.c[i] = op * child.c[i] + k * parent.c[i];
        --top;
    };
    for (int h = (int)hits.size() - 1; h >= 0; --h) {
        enter_layer(sc, stack, top, sc.draws[hits[h].draw].layer, pop, [&](int opened) {
            if (tape) tape->ops.push_back({Tape::PUSH, opened, {}, {}});
        });
        LayerFrame& f = stack[top];
        if (tape) {
            Tape::Op o{Tape::OVER, h, {}, {}};
            for (int i = 0; i < 4; ++i) o.prev[i] = f.c[i];
            tape->ops.push_back(o);
        }
        const double* c = hits[h].c;
        for (int i = 0; i < 4; ++i) f.c[i] = c[i] + (1 - c[3]) * f.c[i];
    }
    while (top > 0) pop();
    for (int i = 0; i < 4; ++i) out[i] = stack[0].c[i];
}

// Adjoint of composite_forward, walking its tape backwards: g is dL/d(result); adds
// dL/d(hit colour) into g_hits and dL/d(layer opacity) into grads.
VF_HD void composite_backward(const SceneView& sc, const Buffer<Hit>& hits, const Tape& tape, const double g[4],
                              Buffer<Quad>& g_hits, const GradView& grads) {
    g_hits.clear();
    for (int k = 0; k < hits.size(); ++k) g_hits.push_back(Quad{{0, 0, 0, 0}});
    double adj[MAX_LAYER_DEPTH][4];
    int top = 0;
    for (int i = 0; i < 4; ++i) adj[0][i] = g[i];
    for (int k = (int)tape.ops.size() - 1; k >= 0; --k) {
        const Tape::Op& o = tape.ops[k];
        double* a = adj[top];
        if (o.kind == Tape::OVER) {
            const double* c = hits[o.ref].c;
            double dp = a[0] * o.prev[0] + a[1] * o.prev[1] + a[2] * o.prev[2] + a[3] * o.prev[3];
            for (int i = 0; i < 4; ++i) g_hits[o.ref][i] += a[i];
            g_hits[o.ref][3] -= dp;
            for (int i = 0; i < 4; ++i) a[i] *= 1 - c[3];
        } else if (o.kind == Tape::POP) {
            double op = sc.layer_opacity[o.ref];
            double dp = a[0] * o.prev[0] + a[1] * o.prev[1] + a[2] * o.prev[2] + a[3] * o.prev[3];
            double dl = a[0] * o.layer[0] + a[1] * o.layer[1] + a[2] * o.layer[2] + a[3] * o.layer[3];
            grads.layer_opacity[o.ref] += dl - o.layer[3] * dp;
            double* child = adj[top + 1];
            for (int i = 0; i < 4; ++i) child[i] = op * a[i];
            child[3] -= op * dp;
            double k2 = 1 - op * o.layer[3];
            for (int i = 0; i < 4; ++i) a[i] *= k2;
            ++top;
        } else {  // PUSH: the layer's frame began empty; back to the parent's adjoint
            --top;
        }
    }
}

// The jump at p when draw `forced` comes to cover it, for scenes without layers:
// composite = F + T (c_d + (1 - a_d) B) with the draw, F + T B without it, where T is
// the transmittance of what lies in front of the draw and B the composite behind it, so
// delta = T (c_d - a_d B). One front-to-back pass that stops as soon as T is 0 (the
// draw is hidden) or B is opaque.
// `inside` is the sample's point a hair inside the draw. A draw behind that covers it but
// not p has an edge of its own through the sample, on the same side: a shape drawn over
// another along part of its outline (mcseem2 is full of them). When every point moves, that
// edge moves with this one, so it counts as covering p in both composites: the copies of
// one edge then add up to its jump once, as a sum that telescopes in paint order (the
// later copy's jump is over the earlier one's colour, not over what lay behind both).
VF_HD void jump_without_layers(const SceneView& sc, const TileView& bins, Vec2 p, Vec2 inside, int forced,
                               double delta[4]) {
    for (int i = 0; i < 4; ++i) delta[i] = 0;
    int tile = tile_of(bins, p);
    Box region = bins.region(tile);
    if (p.x < region.x0 || p.x > region.x1 || p.y < region.y0 || p.y > region.y1) return;
    const bool inside_in_region = inside.x >= region.x0 && inside.x <= region.x1 && inside.y >= region.y0 &&
                                  inside.y <= region.y1;
    const TileEntry* es = bins.begin(tile);
    double T = 1, B[4] = {0, 0, 0, 0}, c[4];
    for (int k = bins.count(tile) - 1; k >= 0; --k) {
        int draw = es[k].draw;
        if (draw == forced) continue;
        if (draw > forced) {  // in front
            if (!covers(sc, bins, es[k], region, p)) continue;
            paint_color(sc, sc.paints[sc.draws[draw].paint], p, c);
            T *= 1 - c[3];
            if (T <= 0) return;
        } else {  // behind
            if (inside_in_region ? !covers_or_edge_to(sc, bins, es[k], region, p, inside)
                                 : !covers(sc, bins, es[k], region, p))
                continue;
            paint_color(sc, sc.paints[sc.draws[draw].paint], p, c);
            double k2 = 1 - B[3];
            for (int i = 0; i < 4; ++i) B[i] += k2 * c[i];
            if (B[3] >= 1) break;
        }
    }
    double cd[4];
    paint_color(sc, sc.paints[sc.draws[forced].paint], p, cd);
    for (int i = 0; i < 4; ++i) delta[i] = T * (cd[i] - cd[3] * B[i]);
}

}  // namespace vf
