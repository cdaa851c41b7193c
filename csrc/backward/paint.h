// The adjoint of paint evaluation (scene/paint.h): dL/d(premultiplied colour) at a point
// to dL/d(paint parameters (the paint_params table), stop offsets, stop colours).
#pragma once

#include <cmath>

#include "backward/grads.h"
#include "common/portable.h"
#include "common/vec.h"
#include "scene/paint.h"
#include "scene/scene.h"

namespace vf {

// d(premultiplied colour)/d(straight colour c) applied to g: the adjoint of c.
// Values are clamped to [0, 1]; the gradient passes where a value lies in [0, 1], ends
// included, so that an opaque alpha or a zero channel can still move inwards.
VF_HD void premultiply_backward(const double c[4], const double g[4], double gc[4]) {
    double a = vclamp(c[3], 0.0, 1.0);
    for (int i = 0; i < 3; ++i) gc[i] = (c[i] >= 0 && c[i] <= 1) ? g[i] * a : 0.0;
    double ga = g[3];
    for (int i = 0; i < 3; ++i) ga += g[i] * vclamp(c[i], 0.0, 1.0);
    gc[3] = (c[3] >= 0 && c[3] <= 1) ? ga : 0.0;
}

// Adjoint of paint_color: g is dL/d(premultiplied colour at `pixel`); adds dL/d(paint
// parameters, stop offsets, stop colours) into grads.
VF_HD void paint_color_backward(const SceneView& sc, int paint_index, Vec2 pixel, const double g[4],
                                const GradView& grads) {
    const PreparedPaint& p = sc.paints[paint_index];
    GradPtr gp = grads.paint_params + PAINT_FCOLS * paint_index;
    if (p.kind == PAINT_SOLID) {
        double gc[4];
        premultiply_backward(p.rgba, g, gc);
        for (int i = 0; i < 4; ++i) gp[6 + i] += gc[i];
        return;
    }
    Vec2 q = apply(p.to_paint, pixel);
    double t;
    Vec2 dt_dq{0, 0};
    double gg[5] = {0, 0, 0, 0, 0};  // dt / d(gradient geometry g[0..4])
    if (p.kind == PAINT_LINEAR) {
        Vec2 a{p.g[0], p.g[1]}, d = Vec2{p.g[2], p.g[3]} - a, e = q - a;
        double D = dot(d, d);
        if (D <= 0) return;  // constant colour: the last stop
        t = dot(e, d) / D;
        dt_dq = (1 / D) * d;
        Vec2 ta = (1 / D) * (-1.0 * d - e + (2 * t) * d), tb = (1 / D) * (e - (2 * t) * d);
        gg[0] = ta.x; gg[1] = ta.y; gg[2] = tb.x; gg[3] = tb.y;
    } else {
        double r = p.g[2];
        Vec2 c{p.g[0], p.g[1]}, f{p.g[3], p.g[4]};
        t = 1.0;
        if (r <= 0 || !radial_t(q, c, r, f, t)) return;
        // F(t) = A t^2 - 2 B t + C = 0 with A = |c-f|^2 - r^2, B = (q-f).(c-f), C = |q-f|^2:
        // dt = -(dF/dparam) / (dF/dt), never differentiating the solve itself.
        Vec2 d = c - f, e = q - f;
        double A = dot(d, d) - r * r, B = dot(e, d);
        double Ft = 2 * A * t - 2 * B;
        if (std::fabs(Ft) < 1e-12) return;
        double k = -1 / Ft;
        // dF/dA = t^2, dF/dB = -2t, dF/dC = 1
        Vec2 dA_dc = 2.0 * d, dB_dc = e;
        Vec2 dA_df = -2.0 * d, dB_df = -1.0 * d - e, dC_df = -2.0 * e;
        Vec2 tc = k * (t * t * dA_dc - 2 * t * dB_dc);
        Vec2 tf = k * (t * t * dA_df - 2 * t * dB_df + dC_df);
        double tr = k * (t * t * (-2 * r));
        dt_dq = k * (-2 * t * d + 2.0 * e);
        gg[0] = tc.x; gg[1] = tc.y; gg[2] = tr; gg[3] = tf.x; gg[4] = tf.y;
    }
    // Stops: straight colour c = (1-u) C_k + u C_{k+1}, u = (t - o_k) / (o_{k+1} - o_k).
    const double* off = sc.stop_offsets.data() + p.first_stop;
    const double* col = sc.stop_colors.data() + 4 * p.first_stop;
    GradPtr g_off = grads.stop_offsets + p.first_stop;
    GradPtr g_col = grads.stop_colors + 4 * p.first_stop;
    int n = p.n_stops;
    double c[4], gc[4];
    if (!(t > off[0]) || t >= off[n - 1]) {  // padded: a constant colour, no t dependence
        int k = !(t > off[0]) ? 0 : n - 1;
        premultiply_backward(col + 4 * k, g, gc);
        for (int i = 0; i < 4; ++i) g_col[4 * k + i] += gc[i];
        return;
    }
    int k = 0;
    while (k + 2 < n && t >= off[k + 1]) ++k;
    double span = off[k + 1] - off[k];
    double u = span > 0 ? (t - off[k]) / span : 1.0;
    for (int i = 0; i < 4; ++i) c[i] = (1 - u) * col[4 * k + i] + u * col[4 * (k + 1) + i];
    premultiply_backward(c, g, gc);
    double gu = 0;
    for (int i = 0; i < 4; ++i) {
        g_col[4 * k + i] += (1 - u) * gc[i];
        g_col[4 * (k + 1) + i] += u * gc[i];
        gu += gc[i] * (col[4 * (k + 1) + i] - col[4 * k + i]);
    }
    if (span <= 0) return;
    g_off[k] += gu * (u - 1) / span;
    g_off[k + 1] += gu * (-u) / span;
    double gt = gu / span;
    for (int i = 0; i < 5; ++i) gp[6 + i] += gt * gg[i];
    // q = M (pixel, 1): dt/dM = dt/dq (outer) (pixel, 1)
    gp[0] += gt * dt_dq.x * pixel.x; gp[1] += gt * dt_dq.x * pixel.y; gp[2] += gt * dt_dq.x;
    gp[3] += gt * dt_dq.y * pixel.x; gp[4] += gt * dt_dq.y * pixel.y; gp[5] += gt * dt_dq.y;
}

}  // namespace vf
