// The forward pass's compositing: draws added front to back under what a sample has so
// far, so that it can stop once the sample is opaque, with nested layers for group
// opacity. (The backward pass composites the same hits back to front with a tape:
// composite_forward / composite_backward in backward/composite.h; the two agree to
// rounding.)
#pragma once

#include "common/portable.h"
#include "scene/layers.h"
#include "scene/scene.h"

namespace vf {

// Front-to-back compositing with a stack of open layers. Each frame accumulates the
// premultiplied colour of its layer; closing a layer scales it by the layer's opacity
// and puts it under what its parent has so far.
struct FrontToBackCompositor {
    const SceneView& sc;
    LayerFrame stack[MAX_LAYER_DEPTH];
    int top = 0;

    VF_HD explicit FrontToBackCompositor(const SceneView& s) : sc(s) {
        stack[0].layer = 0;
        for (int i = 0; i < 4; ++i) stack[0].c[i] = 0;
    }

    VF_HD void pop() {
        LayerFrame& child = stack[top--];
        LayerFrame& parent = stack[top];
        double k = (1 - parent.c[3]) * sc.layer_opacity[child.layer];
        for (int i = 0; i < 4; ++i) parent.c[i] += k * child.c[i];
    }

    VF_HD void enter(int layer) {
        enter_layer(sc, stack, top, layer, [&] { pop(); }, [](int) {});
    }

    // Adds a premultiplied colour under what the current layer has.
    VF_HD void under(const double c[4], double coverage) {
        LayerFrame& f = stack[top];
        double k = (1 - f.c[3]) * coverage;
        for (int i = 0; i < 4; ++i) f.c[i] += k * c[i];
    }

    VF_HD bool opaque() const { return top == 0 && stack[0].c[3] >= 1 - 1e-12; }

    VF_HD void finish(double out[4]) {
        while (top > 0) pop();
        for (int i = 0; i < 4; ++i) out[i] = stack[0].c[i];
    }
};

}  // namespace vf
