// Walking the layer tree (group opacity): shared by the forward compositor and the
// backward pass's tape.
#pragma once

#include "scene/scene.h"

namespace vf {

constexpr int MAX_LAYER_DEPTH = 64;  // prepare_scene refuses deeper nesting

// Whether layer `ancestor` is `l` or one of its ancestors.
VF_HD bool layer_contains(const SceneView& sc, int ancestor, int l) {
    while (sc.layer_depth[l] > sc.layer_depth[ancestor]) l = sc.layer_parent[l];
    return l == ancestor;
}

// A layer being composited: its premultiplied colour so far.
struct LayerFrame {
    int layer;
    double c[4];
};

// The layers below the open layer `open` down to `layer` (which `open` contains), the
// outermost first; returns their count.
VF_HD int layers_between(const SceneView& sc, int open, int layer, int* out) {
    int n = 0;
    for (int l = layer; l != open; l = sc.layer_parent[l]) out[n++] = l;
    for (int i = 0; i < n / 2; ++i) vswap(out[i], out[n - 1 - i]);
    return n;
}

// Makes `layer` the top of the stack of open layers (stack[0..top]): closes those that do
// not contain it (close(), which pops), then opens empty frames down to it, calling
// opened(layer) for each.
template <class Close, class Opened>
VF_HD void enter_layer(const SceneView& sc, LayerFrame* stack, int& top, int layer, Close close, Opened opened) {
    if (stack[top].layer == layer) return;
    while (!layer_contains(sc, stack[top].layer, layer)) close();
    int chain[MAX_LAYER_DEPTH];
    int n = layers_between(sc, stack[top].layer, layer, chain);
    for (int i = 0; i < n; ++i) {
        LayerFrame& f = stack[++top];
        f.layer = chain[i];
        for (int j = 0; j < 4; ++j) f.c[j] = 0;
        opened(f.layer);
    }
}

}  // namespace vf
