// Walking the layer tree (group opacity): shared by the forward compositor and the
// backward pass's tape.
#pragma once

#include "scene.h"

namespace vf {

constexpr int MAX_LAYER_DEPTH = 64;  // prepare_scene refuses deeper nesting

// Whether layer `ancestor` is `l` or one of its ancestors.
VF_HD bool layer_contains(const SceneView& sc, int ancestor, int l) {
    while (sc.layer_depth[l] > sc.layer_depth[ancestor]) l = sc.layer_parent[l];
    return l == ancestor;
}

// The layers below the open layer `open` down to `layer` (which `open` contains), the
// outermost first; returns their count.
VF_HD int layers_between(const SceneView& sc, int open, int layer, int* out) {
    int n = 0;
    for (int l = layer; l != open; l = sc.layer_parent[l]) out[n++] = l;
    for (int i = 0; i < n / 2; ++i) vswap(out[i], out[n - 1 - i]);
    return n;
}

}  // namespace vf
