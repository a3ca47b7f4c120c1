// Deterministic quadrature of one shading point over the environment pyramid (lobe_quadrature.h).
#include "renderers/reference/lobe_quadrature.h"

#include <cmath>
#include <vector>

#include "renderers/reference/adaptive_refine.h"

namespace iblcheck::truth {

namespace {

constexpr int kDeepest = 14;
// The guard grades the mesh out to this many lobe widths from the peak; beyond, GGX's tail is smooth
// on the scale of the distance and the indicator alone decides.
constexpr double kGuardReach = 8;
// Across the plane of incidence the lobe narrows as n·v; the guard stops following it below this n·v
// (grazing points cover little of the image, and the indicator still refines where they need it).
constexpr double kMinWidthNv = 0.05; // sub-texel levels: a texel splits into at most 2^14 x 2^14 cells

// The part of a cell above the horizon of n, the cell taken as its tangent-plane rectangle (second
// order in its size): n·l ≈ d + a·x + b·y is clipped against the rectangle (Sutherland–Hodgman);
// returns the fraction of the cell above the horizon and, when > 0, that part's centroid direction.
double clip_above_horizon(const EnvPyramid::Rect& r, V3 n, V3& centroid) {
    const double d = dot(n, r.g), a = dot(n, r.ex), b = dot(n, r.ey);
    double px[8], py[8];
    int m = 0;
    const double cx[4] = {-r.hx, r.hx, r.hx, -r.hx}, cy[4] = {-r.hy, -r.hy, r.hy, r.hy};
    for (int k = 0; k < 4; ++k) {
        const int k1 = (k + 1) & 3;
        const double h0 = d + a * cx[k] + b * cy[k], h1 = d + a * cx[k1] + b * cy[k1];
        if (h0 >= 0) px[m] = cx[k], py[m] = cy[k], ++m;
        if ((h0 >= 0) != (h1 >= 0)) {
            const double t = h0 / (h0 - h1);
            px[m] = cx[k] + t * (cx[k1] - cx[k]), py[m] = cy[k] + t * (cy[k1] - cy[k]), ++m;
        }
    }
    double area = 0, sx = 0, sy = 0;
    for (int k = 0; k < m; ++k) {
        const int k1 = (k + 1) % m;
        const double c = px[k] * py[k1] - px[k1] * py[k];
        area += c, sx += (px[k] + px[k1]) * c, sy += (py[k] + py[k1]) * c;
    }
    area *= 0.5;
    if (m < 3 || area <= 0) return 0;
    centroid = normalize(r.g + (sx / (6 * area)) * r.ex + (sy / (6 * area)) * r.ey);
    return area / (4 * r.hx * r.hy);
}

// A cell of the pyramid (level ≥ 0) or a sub-texel cell (level −s: texel (i, j), sub-cell (a, b) of
// 2^s × 2^s), with its estimates (adaptive_refine.h's Region).
struct EnvRegion {
    double fine[3];
    double indicator;
    bool forced, splittable, lazy;
    int level, i, j, a, b;
    int nkids;
    int kid[4][5];      // the children's (level, i, j, a, b)
    double kid_e[4][3]; // their one-point estimates
};

struct Integrand {
    const EnvPyramid& env;
    const MaterialLobe& lobe;
    const ShadingPoint& s;
    const QuadratureParams& p;
    V3 peak;              // mirror direction: the GGX lobe's core
    double cos_guard_w;   // cos(κ·w)
    double w;             // the lobe's width (the far part: the window's transition width)
    bool guard;
    double one_minus_cos_window = 0; // 1 − cos(window radius)
    long evals = 0;

    // The near/far split's weights of the specular term at direction l (lobe_quadrature.h): W(σ),
    // σ = (1 − l·peak)/(1 − cos R) (≈ (angle/R)²), W = 1 for σ ≤ 1/4, 0 for σ ≥ 1, quintic smoothstep
    // in u = (1 − σ)/(3/4) between; its complement for the far part.
    void f(V3 l, double out[3]) const {
        if (p.part == LobePart::whole) return fcos(lobe, s, l, out);
        const double sig = (1 - dot(l, peak)) / one_minus_cos_window;
        double W = 1;
        if (sig >= 1) W = 0;
        else if (sig > 0.25) {
            const double u = (1 - sig) / 0.75;
            W = u * u * u * (10 - 15 * u + 6 * u * u);
        }
        if (p.part == LobePart::near) fcos(lobe, s, l, out, W, 0.0);
        else fcos(lobe, s, l, out, 1 - W, 1.0);
    }
    // The near part: is the cell (geometric centre g, cos of radius cr) outside the window?
    bool outside_window(V3 g, double cr) const {
        if (p.part != LobePart::near) return false;
        const double cw = 1 - one_minus_cos_window, sw = std::sqrt(std::max(0.0, 1 - cw * cw));
        const double sr = std::sqrt(std::max(0.0, 1 - cr * cr));
        const double cos_sum = cw * cr - sw * sr; // cos(R + radius)
        return std::acos(std::clamp(cw, -1.0, 1.0)) + std::acos(std::clamp(cr, -1.0, 1.0)) < kPi && dot(g, peak) < cos_sum;
    }

    // A cell's estimate; false if the cell is entirely below the horizon or black (no region). Levels
    // ≥ 0: four points matching the cell's luminance-weighted mean direction c and second moment C
    // (projected on c's tangent plane, Cholesky factor columns l₁, l₂): c ± √2·l_k, each weighted ∫L/4 —
    // exact for a BRDF quadratic over the cell, so fourth order where it is smooth (the unscented
    // transform's sigma points); a point source gives four coincident points, evaluated once.
    // Sub-texel cells: 2x2 Gauss–Legendre of the bilinear radiance. A cell that straddles the horizon:
    // f·cos at the centroid of its part above, times that part's fraction (the cosine's kink would make
    // any smooth rule first order there, and hide an upper part whose points all fall below).
    bool estimate(int level, int i, int j, int a, int b, double e[3]) {
        double cr, L[3] = {0, 0, 0}, f[3];
        V3 g, pts[4];
        double wL[4][3];
        const EnvCell* cell = nullptr;
        if (level >= 0) {
            cell = &env.cell(level, i, j);
            if (cell->L[0] == 0 && cell->L[1] == 0 && cell->L[2] == 0) return false;
            g = {cell->g[0], cell->g[1], cell->g[2]};
            cr = cell->cos_radius;
            for (int q = 0; q < 3; ++q) L[q] = cell->L[q];
        } else {
            const int n = 1 << -level;
            g = env.dir_in_texel(i, (a + 0.5) / n, j, (b + 0.5) / n);
            cr = std::cos(env.subcell_radius(j, n, b));
            env.subcell_gauss(i, j, n, a, b, pts, wL);
            for (int k = 0; k < 4; ++k)
                for (int q = 0; q < 3; ++q) L[q] += wL[k][q];
        }
        const double sr = std::sqrt(std::max(0.0, 1 - cr * cr)), h = dot(g, s.n);
        if (h < -sr) return false; // angle to n > 90° + radius
        if (outside_window(g, cr)) return false;
        if (h < sr) { // straddles the horizon
            V3 c;
            const double frac = clip_above_horizon(env.rect(level, i, j, a, b), s.n, c);
            if (frac <= 0) return false;
            ++evals;
            this->f(c, f);
            for (int q = 0; q < 3; ++q) e[q] = f[q] * L[q] * frac;
            return true;
        }
        e[0] = e[1] = e[2] = 0;
        if (level < 0) {
            for (int k = 0; k < 4; ++k) {
                this->f(pts[k], f);
                for (int q = 0; q < 3; ++q) e[q] += f[q] * wL[k][q];
            }
            evals += 4;
            return true;
        }
        for (int k = 0; k < cell->np; ++k) {
            this->f(V3{cell->sp[k][0], cell->sp[k][1], cell->sp[k][2]}, f);
            for (int q = 0; q < 3; ++q) e[q] += f[q];
        }
        evals += cell->np;
        for (int q = 0; q < 3; ++q) e[q] *= L[q] / cell->np;
        return true;
    }

    // The guard (a graded mesh about the lobe's peak): a cell must be no wider than κ·max(w, d), d its
    // closest angular distance to the peak — κ·w on the lobe's core, growing with the distance in its
    // tails, where GGX's D varies on the scale of that distance.
    bool forced(int level, int i, int j, int a, int b) const {
        if (!guard) return false;
        V3 g;
        double radius;
        if (level >= 0) {
            const EnvCell& c = env.cell(level, i, j);
            g = {c.g[0], c.g[1], c.g[2]};
            if (c.cos_radius >= cos_guard_w) return false; // radius ≤ κ·w: resolved wherever it is
            radius = std::acos(std::clamp(double(c.cos_radius), -1.0, 1.0));
        } else {
            const int n = 1 << -level;
            radius = env.subcell_radius(j, n, b);
            if (radius <= p.kappa * w) return false;
            g = env.dir_in_texel(i, (a + 0.5) / n, j, (b + 0.5) / n);
        }
        const double d = std::max(0.0, std::acos(std::clamp(dot(g, peak), -1.0, 1.0)) - radius);
        return d < kGuardReach * w && radius > p.kappa * std::max(w, d);
    }

    void children(int level, int i, int j, int a, int b, int out[4][5], int& n) const {
        n = 0;
        if (level > 0) {
            for (int db = 0; db < 2; ++db)
                for (int da = 0; da < 2; ++da) {
                    const int ii = 2 * i + da, jj = 2 * j + db;
                    if (ii < env.width(level - 1) && jj < env.height(level - 1)) {
                        int* k = out[n++];
                        k[0] = level - 1, k[1] = ii, k[2] = jj, k[3] = 0, k[4] = 0;
                    }
                }
        } else {
            for (int db = 0; db < 2; ++db)
                for (int da = 0; da < 2; ++da) {
                    int* k = out[n++];
                    k[0] = level - 1, k[1] = i, k[2] = j, k[3] = level == 0 ? da : 2 * a + da, k[4] = level == 0 ? db : 2 * b + db;
                }
        }
    }

    // A region with its one-point estimate e1: evaluates its children for the fine estimate.
    void evaluate_children(EnvRegion& r) {
        int ks[4][5], n;
        children(r.level, r.i, r.j, r.a, r.b, ks, n);
        r.nkids = 0;
        r.fine[0] = r.fine[1] = r.fine[2] = 0;
        for (int k = 0; k < n; ++k) {
            double e[3];
            if (!estimate(ks[k][0], ks[k][1], ks[k][2], ks[k][3], ks[k][4], e)) continue;
            std::copy(ks[k], ks[k] + 5, r.kid[r.nkids]);
            for (int q = 0; q < 3; ++q) r.kid_e[r.nkids][q] = e[q], r.fine[q] += e[q];
            ++r.nkids;
        }
    }

    // A forced region is split before anything else, so its children are evaluated only then (lazy).
    EnvRegion region(int level, int i, int j, int a, int b, const double e1[3]) {
        EnvRegion r{};
        r.level = level, r.i = i, r.j = j, r.a = a, r.b = b;
        // Every cell can be split, down to 2^-14 of a texel: a cell that could not would hide its error.
        r.forced = forced(level, i, j, a, b);
        r.splittable = level > -kDeepest;
        if (r.splittable && r.forced) {
            r.lazy = true;
            for (int q = 0; q < 3; ++q) r.fine[q] = e1[q];
        } else if (r.splittable) {
            evaluate_children(r);
            double d[3] = {r.fine[0] - e1[0], r.fine[1] - e1[1], r.fine[2] - e1[2]};
            r.indicator = rgb_size(d);
        } else {
            r.forced = false;
            for (int q = 0; q < 3; ++q) r.fine[q] = e1[q];
        }
        return r;
    }
};

} // namespace

void shade(const EnvPyramid& env, const MaterialLobe& lobe, const ShadingPoint& s, const QuadratureParams& p, double rgb[3],
           ShadeStats* stats) {
    if (lobe.mirror && lobe.specular) {
        // Delta lobe: ∫ D V F (n·l) L dl → F(n·v) L(reflect(v)) (G2 = 1 at α = 0).
        const V3 r = 2 * s.nv * s.n - s.v;
        double L[3];
        env.radiance(r, L);
        for (int q = 0; q < 3; ++q) rgb[q] += model::f_schlick(lobe.f0[q], s.nv) * L[q];
    }
    if (!lobe.diffuse && !lobe.glossy()) return;
    if (p.part == LobePart::near && !lobe.glossy()) return;
    Integrand in{env, lobe, s, p, 2 * s.nv * s.n - s.v, 1, 0, lobe.glossy()};
    in.w = 2 * lobe.alpha * std::max(s.nv, kMinWidthNv);
    if (p.part != LobePart::whole) {
        const double R = std::min(kPi / 2, p.window * in.w);
        in.one_minus_cos_window = 1 - std::cos(R);
        if (p.part == LobePart::far) in.w = std::max(in.w, R / 4); // the window's transition: its finest feature
    }
    in.cos_guard_w = std::cos(p.kappa * in.w);
    thread_local std::vector<EnvRegion> heap;
    heap.clear();
    const int top = env.top_level();
    if (p.part == LobePart::near) {
        // Only the window matters: start from the cells of the level about half its radius wide.
        const double R = std::acos(1 - in.one_minus_cos_window);
        int level = top;
        while (level > 0 && env.cell_angle(level) > R / 2) --level;
        thread_local std::vector<std::pair<int, int>> cells;
        env.cone_cells(in.peak, R, level, cells);
        for (auto [i, j] : cells) {
            double e[3];
            if (in.estimate(level, i, j, 0, 0, e)) heap.push_back(in.region(level, i, j, 0, 0, e));
        }
    } else {
        for (int j = 0; j < env.height(top); ++j)
            for (int i = 0; i < env.width(top); ++i) {
                double e[3];
                if (in.estimate(top, i, j, 0, 0, e)) heap.push_back(in.region(top, i, j, 0, 0, e));
            }
    }
    auto split = [&](const EnvRegion& parent, std::vector<EnvRegion>& out) {
        EnvRegion r = parent;
        if (r.lazy) in.evaluate_children(r);
        for (int k = 0; k < r.nkids; ++k) {
            const int* c = r.kid[k];
            out.push_back(in.region(c[0], c[1], c[2], c[3], c[4], r.kid_e[k]));
        }
    };
    const RefineOutcome o = refine(heap, split, p.tolerance, p.floor, p.max_splits);
    for (int q = 0; q < 3; ++q) rgb[q] += o.value[q];
    if (stats) {
        stats->evaluations += in.evals;
        stats->splits += long(o.splits);
        stats->error += o.error;
        stats->budget_hit |= o.budget_hit;
    }
}

} // namespace iblcheck::truth
