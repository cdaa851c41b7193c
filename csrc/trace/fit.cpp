// The level-by-level Bézier fit of bezier.py's _fit_all, moved from NumPy (0.1-0.2 s of
// a photo's trace, in array operations a few dozen points long). It computes what the
// NumPy code computed, bit for bit, so traces stay byte-identical: the same double
// operations in the same order (built without floating-point contraction: see
// CMakeLists.txt), sums over a piece as np.add.reduceat makes them (numpy's pairwise
// summation), and the pieces of a level reparameterised together, as the NumPy code's
// Newton steps stop only once every piece of the level that needed them is within
// tolerance.
#include "trace/fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace vf {
namespace {

struct P2 {
    double x, y;
};

// numpy's pairwise summation (loops_utils.h: DOUBLE_pairwise_sum), of n values
double pairwise_sum(const double* a, int64_t n) {
    if (n < 8) {
        double res = 0.;
        for (int64_t i = 0; i < n; ++i) res += a[i];
        return res;
    }
    if (n <= 128) {
        double r[8];
        for (int j = 0; j < 8; ++j) r[j] = a[j];
        int64_t i = 8;
        for (; i < n - (n % 8); i += 8)
            for (int j = 0; j < 8; ++j) r[j] += a[i + j];
        double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; ++i) res += a[i];
        return res;
    }
    int64_t n2 = n / 2;
    n2 -= n2 % 8;
    return pairwise_sum(a, n2) + pairwise_sum(a + n2, n - n2);
}

// np.add.reduceat over one segment: its first value, plus the pairwise sum of the rest
double segment_sum(const std::vector<double>& v) { return v[0] + pairwise_sum(v.data() + 1, (int64_t)v.size() - 1); }

struct Basis {
    double b0, b1, b2, b3;
};

Basis basis(double u) {
    const double mu = 1 - u;
    return {mu * mu * mu, 3 * mu * mu * u, 3 * mu * u * u, u * u * u};
}

// One piece: points a..b of the stretch points, with its end tangents.
struct Piece {
    int64_t a, b;
    P2 t1, t2;
    int64_t owner;
};

struct Curve {
    P2 c[4];
};

class Fitter {
public:
    explicit Fitter(const FitInput& in) : in_(in), tol2_(in.options.tolerance * in.options.tolerance) {}

    FitResult run() {
        std::vector<Piece> level;
        for (int64_t k = 0; k < in_.stretches; ++k)
            level.push_back({in_.first[k], in_.first[k] + in_.lengths[k] - 1, {in_.t1[2 * k], in_.t1[2 * k + 1]},
                             {in_.t2[2 * k], in_.t2[2 * k + 1]}, k});
        while (!level.empty()) level = fit_level(level);
        // by stretch, then along it
        std::vector<size_t> order(done_.size());
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(), [&](size_t i, size_t j) {
            return done_[i].owner != done_[j].owner ? done_[i].owner < done_[j].owner : done_[i].start < done_[j].start;
        });
        FitResult out;
        out.ctrl.reserve(order.size() * 8);
        for (size_t i : order) {
            for (const P2& p : done_[i].curve.c) {
                out.ctrl.push_back(p.x);
                out.ctrl.push_back(p.y);
            }
            out.owner.push_back(done_[i].owner);
        }
        return out;
    }

private:
    struct Done {
        Curve curve;
        int64_t start, owner;
    };

    // A piece being fitted: its parameters, errors and curve points at them.
    struct State {
        std::vector<double> u, err;
        std::vector<P2> at;
        Curve curve;
        double worst;
    };

    P2 point(int64_t i) const { return {in_.points[2 * i], in_.points[2 * i + 1]}; }
    P2 tangent(int64_t i) const { return {in_.tangents[2 * i], in_.tangents[2 * i + 1]}; }

    // bezier.py's _least_squares for one piece
    Curve least_squares(const Piece& pc, const std::vector<double>& u, double length) {
        const int64_t n = pc.b - pc.a + 1;
        const P2 p0 = point(pc.a), p3 = point(pc.b);
        s11_.resize(n), s22_.resize(n), s12_.resize(n), sx1_.resize(n), sx2_.resize(n);
        for (int64_t i = 0; i < n; ++i) {
            const Basis q = basis(u[i]);
            const P2 p = point(pc.a + i);
            const double rx = p.x - (q.b0 + q.b1) * p0.x - (q.b2 + q.b3) * p3.x;
            const double ry = p.y - (q.b0 + q.b1) * p0.y - (q.b2 + q.b3) * p3.y;
            s11_[i] = q.b1 * q.b1;
            s22_[i] = q.b2 * q.b2;
            s12_[i] = q.b1 * q.b2;
            sx1_[i] = q.b1 * (rx * pc.t1.x + ry * pc.t1.y);
            sx2_[i] = q.b2 * (rx * pc.t2.x + ry * pc.t2.y);
        }
        const double c11 = segment_sum(s11_), c22 = segment_sum(s22_);
        const double c12 = segment_sum(s12_) * (pc.t1.x * pc.t2.x + pc.t1.y * pc.t2.y);
        const double x1 = segment_sum(sx1_), x2 = segment_sum(sx2_);
        const double det = c11 * c22 - c12 * c12;
        const bool ok = std::fabs(det) > 1e-12;
        double al1 = ok ? (x1 * c22 - x2 * c12) / det : -1.0;
        double al2 = ok ? (c11 * x2 - c12 * x1) / det : -1.0;
        const double chord = std::hypot(p3.x - p0.x, p3.y - p0.y);
        const double low = 1e-3 * std::max(chord, 1e-9), high = std::max(2 * chord, length);
        // wild solutions (handles backwards or far out, which make loops): thirds of the chord
        if (!((low < al1) && (al1 < high) && (low < al2) && (al2 < high))) al1 = al2 = chord / 3;
        return {{p0, {p0.x + al1 * pc.t1.x, p0.y + al1 * pc.t1.y}, {p3.x + al2 * pc.t2.x, p3.y + al2 * pc.t2.y}, p3}};
    }

    // bezier.py's _errors: squared distances and curve points at u; returns the worst
    double errors(const Piece& pc, const Curve& cv, const std::vector<double>& u, std::vector<double>& err,
                  std::vector<P2>& at) const {
        const int64_t n = pc.b - pc.a + 1;
        err.resize(n), at.resize(n);
        double worst = -std::numeric_limits<double>::infinity();
        for (int64_t i = 0; i < n; ++i) {
            const Basis q = basis(u[i]);
            const P2* c = cv.c;
            at[i] = {q.b0 * c[0].x + q.b1 * c[1].x + q.b2 * c[2].x + q.b3 * c[3].x,
                     q.b0 * c[0].y + q.b1 * c[1].y + q.b2 * c[2].y + q.b3 * c[3].y};
            const P2 p = point(pc.a + i);
            const double dx = at[i].x - p.x, dy = at[i].y - p.y;
            err[i] = dx * dx + dy * dy;
            worst = i == 0 ? err[i] : std::max(worst, err[i]);
        }
        return worst;
    }

    // bezier.py's _newton: one step per point towards its closest curve point
    void newton(const Piece& pc, const State& s, std::vector<double>& u2) const {
        const int64_t n = pc.b - pc.a + 1;
        const P2* c = s.curve.c;
        P2 d1[3], d2[2];
        for (int j = 0; j < 3; ++j) d1[j] = {3 * (c[j + 1].x - c[j].x), 3 * (c[j + 1].y - c[j].y)};
        for (int j = 0; j < 2; ++j) d2[j] = {2 * (d1[j + 1].x - d1[j].x), 2 * (d1[j + 1].y - d1[j].y)};
        u2.resize(n);
        for (int64_t i = 0; i < n; ++i) {
            if (i == 0 || i == n - 1) {  // the ends stay put
                u2[i] = i == 0 ? 0.0 : 1.0;
                continue;
            }
            const double uu = s.u[i], mu = 1 - uu;
            const P2 q1 = {mu * mu * d1[0].x + 2 * mu * uu * d1[1].x + uu * uu * d1[2].x,
                           mu * mu * d1[0].y + 2 * mu * uu * d1[1].y + uu * uu * d1[2].y};
            const P2 q2 = {mu * d2[0].x + uu * d2[1].x, mu * d2[0].y + uu * d2[1].y};
            const P2 p = point(pc.a + i);
            const double dx = s.at[i].x - p.x, dy = s.at[i].y - p.y;
            const double num = dx * q1.x + dy * q1.y;
            const double den = (q1.x * q1.x + q1.y * q1.y) + (dx * q2.x + dy * q2.y);
            double v = uu - (std::fabs(den) > 1e-12 ? num / den : 0.0);
            v = v > 0 ? v : 0.0;  // np.clip
            u2[i] = v < 1 ? v : 1.0;
        }
    }

    std::vector<Piece> fit_level(const std::vector<Piece>& level) {
        std::vector<Piece> pieces;
        for (const Piece& pc : level) {
            if (pc.b - pc.a < 2) {  // two points: a line
                const P2 p0 = point(pc.a), p3 = point(pc.b);
                done_.push_back({{{p0,
                                   {p0.x + (p3.x - p0.x) / 3, p0.y + (p3.y - p0.y) / 3},
                                   {p3.x + (p0.x - p3.x) / 3, p3.y + (p0.y - p3.y) / 3},
                                   p3}},
                                 pc.a, pc.owner});
            } else {
                pieces.push_back(pc);
            }
        }
        std::vector<State> state(pieces.size());
        std::vector<double> length(pieces.size());
        std::vector<size_t> retry;
        for (size_t k = 0; k < pieces.size(); ++k) {
            const Piece& pc = pieces[k];
            State& s = state[k];
            length[k] = in_.arc[pc.b] - in_.arc[pc.a];
            const double scale = std::max(length[k], 1e-12);
            s.u.resize(pc.b - pc.a + 1);
            for (int64_t i = pc.a; i <= pc.b; ++i) s.u[i - pc.a] = (in_.arc[i] - in_.arc[pc.a]) / scale;
            s.curve = least_squares(pc, s.u, length[k]);
            s.worst = errors(pc, s.curve, s.u, s.err, s.at);
            const double range = in_.options.newton_range;
            if (s.worst > tol2_ && s.worst < range * range * tol2_) retry.push_back(k);
        }
        // reparameterise the pieces close to the tolerance, keeping improvements; all
        // of them step until every one is within tolerance
        State trial;
        for (int step = 0; step < in_.options.newton_steps && !retry.empty(); ++step) {
            bool all_within = true;
            for (size_t k : retry) {
                const Piece& pc = pieces[k];
                State& s = state[k];
                newton(pc, s, trial.u);
                trial.curve = least_squares(pc, trial.u, length[k]);
                trial.worst = errors(pc, trial.curve, trial.u, trial.err, trial.at);
                if (trial.worst < s.worst) std::swap(s, trial);
                all_within = all_within && s.worst <= tol2_;
            }
            if (all_within) break;
        }
        std::vector<Piece> next, right;
        for (size_t k = 0; k < pieces.size(); ++k) {
            const Piece& pc = pieces[k];
            const State& s = state[k];
            const int64_t n = pc.b - pc.a + 1;
            // a piece that turns too far is split halfway through its turn without being judged
            const double turn = in_.heading[pc.b] - in_.heading[pc.a];
            const bool looping = std::fabs(turn) > in_.options.max_turn && n > 3;
            if ((s.worst <= tol2_ || n <= 3) && !looping) {
                done_.push_back({s.curve, pc.a, pc.owner});
                continue;
            }
            // split at the worst inner point, or the middle of the turn (the first of equals)
            double best = 0;
            int64_t at = -1;
            for (int64_t i = 0; i < n; ++i) {
                const bool inner = i != 0 && i != n - 1;
                double score;
                if (looping)
                    score = inner ? -std::fabs(in_.heading[pc.a + i] - in_.heading[pc.a] - turn / 2)
                                  : -std::numeric_limits<double>::infinity();
                else
                    score = inner ? s.err[i] : -1.0;
                if (at < 0 || score > best) best = score, at = i;
            }
            const int64_t split = std::min(std::max(pc.a + at, pc.a + 1), std::max(pc.b - 1, pc.a + 1));
            const P2 tk = tangent(split);
            next.push_back({pc.a, split, pc.t1, {-tk.x, -tk.y}, pc.owner});
            right.push_back({split, pc.b, tk, pc.t2, pc.owner});
        }
        next.insert(next.end(), right.begin(), right.end());
        return next;
    }

    const FitInput& in_;
    const double tol2_;
    std::vector<Done> done_;
    std::vector<double> s11_, s22_, s12_, sx1_, sx2_;  // per-point terms of a piece's sums
};

}  // namespace

FitResult fit_stretches(const FitInput& in) { return Fitter(in).run(); }

}  // namespace vf
