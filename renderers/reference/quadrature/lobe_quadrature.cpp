// Deterministic quadrature of one shading point over the environment pyramid (lobe_quadrature.h).
#include "renderers/reference/quadrature/lobe_quadrature.h"

#include <cmath>
#include <vector>

#include "kernel/multiversion.h"
#include "renderers/reference/quadrature/adaptive_refine.h"

namespace iblcheck::truth {

namespace {

constexpr int kDeepest = 14;
// The guard grades the mesh out to this many lobe widths from the peak; beyond, GGX's tail is smooth
// on the scale of the distance and the indicator alone decides.
constexpr double kGuardReach = 8;
// Across the plane of incidence the lobe narrows as n·v; the guard stops following it below this n·v
// (grazing points cover little of the image, and the indicator still refines where they need it).
constexpr double kMinWidthNv = 0.25; // sub-texel levels: a texel splits into at most 2^14 x 2^14 cells

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

// f·cos⁺ (truth_math.h, fcos) at four directions at once: structure-of-arrays and branch-free (the
// horizon is a max(0, ·) mask), so the compiler vectorises it; GCC's target_clones (IBLCHECK_CLONES_HASWELL) adds an AVX2+FMA
// version picked at run time on machines that have it (the results differ from the default version's
// in the last bits; each is deterministic).
IBLCHECK_CLONES_HASWELL void fcos4(const MaterialLobe& L, const ShadingPoint& s, const double* lx, const double* ly,
                                   const double* lz, double out[3][4]) {
    double nl[4];
    for (int k = 0; k < 4; ++k) nl[k] = std::max(0.0, s.n.x * lx[k] + s.n.y * ly[k] + s.n.z * lz[k]);
    for (int q = 0; q < 3; ++q)
        for (int k = 0; k < 4; ++k) out[q][k] = L.kd[q] * nl[k];
    if (!L.glossy()) return;
    const double a2 = L.a2;
    double dvn[4], x5[4];
    for (int k = 0; k < 4; ++k) {
        const double hx = lx[k] + s.v.x, hy = ly[k] + s.v.y, hz = lz[k] + s.v.z;
        const double inv = 1.0 / std::sqrt(hx * hx + hy * hy + hz * hz + 1e-300);
        const double nh = (s.n.x * hx + s.n.y * hy + s.n.z * hz) * inv, vh = (s.v.x * hx + s.v.y * hy + s.v.z * hz) * inv;
        const double t = nh * nh * (a2 - 1) + 1;
        const double d = a2 / (kPi * t * t);
        const double vis = 0.5 / (nl[k] * s.gv + s.nv * std::sqrt(nl[k] * nl[k] * (1 - a2) + a2));
        const double x = 1 - std::min(1.0, std::max(0.0, vh));
        x5[k] = x * x * x * x * x;
        dvn[k] = d * vis * nl[k];
        if (L.prefilter) dvn[k] = d * nl[k] * L.inv_norm; // split_sum.h: D·(n·l)/norm, no V, no F
    }
    if (L.prefilter) {
        for (int q = 0; q < 3; ++q)
            for (int k = 0; k < 4; ++k) out[q][k] += dvn[k];
        return;
    }
    for (int q = 0; q < 3; ++q)
        for (int k = 0; k < 4; ++k) out[q][k] += dvn[k] * (L.f0[q] + (1 - L.f0[q]) * x5[k]);
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
    V3 peak;            // mirror direction: the GGX lobe's core
    double cos_guard_w; // cos(κ·w)
    double w;           // the lobe's width
    bool guard;
    long evals = 0;

    // A cell's estimate; false if the cell is entirely below the horizon or black (no region). Levels
    // ≥ 0: four points matching the cell's luminance-weighted mean direction c and second moment C
    // (projected on c's tangent plane, Cholesky factor columns l₁, l₂): c ± √2·l_k, each weighted ∫L/4 —
    // exact for a BRDF quadratic over the cell, so fourth order where it is smooth (the unscented
    // transform's sigma points); a point source gives four coincident points, evaluated once. Each
    // channel q reweights the same points, ∫L_q·(1/4 ± a_q, 1/4 ± b_q) (EnvCell::wa), so that its rule
    // has the channel's own mean direction: a cell whose colour changes across it (blue sky beside
    // green foliage) is then as accurate per channel as in luminance, which halved the evaluations per
    // table node on Blender's forest (CONVERGENCE.md).
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
            cr = env.subcell_cos_radius(j, n);
            env.subcell_gauss(i, j, n, a, b, pts, wL);
            for (int k = 0; k < 4; ++k)
                for (int q = 0; q < 3; ++q) L[q] += wL[k][q];
        }
        const double sr = std::sqrt(std::max(0.0, 1 - cr * cr)), h = dot(g, s.n);
        if (h < -sr) return false; // angle to n > 90° + radius
        if (h < sr) {              // straddles the horizon
            V3 c;
            const double frac = clip_above_horizon(env.rect(level, i, j, a, b), s.n, c);
            if (frac <= 0) return false;
            ++evals;
            fcos(lobe, s, c, f);
            for (int q = 0; q < 3; ++q) e[q] = f[q] * L[q] * frac;
            return true;
        }
        e[0] = e[1] = e[2] = 0;
        double lx[4], ly[4], lz[4], f4[3][4];
        if (level < 0) {
            for (int k = 0; k < 4; ++k) lx[k] = pts[k].x, ly[k] = pts[k].y, lz[k] = pts[k].z;
            fcos4(lobe, s, lx, ly, lz, f4);
            for (int k = 0; k < 4; ++k)
                for (int q = 0; q < 3; ++q) e[q] += f4[q][k] * wL[k][q];
            evals += 4;
            return true;
        }
        if (cell->np == 1) {
            fcos(lobe, s, V3{cell->sp[0][0], cell->sp[0][1], cell->sp[0][2]}, f);
            for (int q = 0; q < 3; ++q) e[q] = f[q] * L[q];
            ++evals;
            return true;
        }
        for (int k = 0; k < 4; ++k) lx[k] = cell->sp[k][0], ly[k] = cell->sp[k][1], lz[k] = cell->sp[k][2];
        fcos4(lobe, s, lx, ly, lz, f4);
        for (int q = 0; q < 3; ++q) {
            const double a = cell->wa[q][0], b = cell->wa[q][1];
            e[q] = L[q] * ((0.25 + a) * f4[q][0] + (0.25 - a) * f4[q][1] + (0.25 + b) * f4[q][2] + (0.25 - b) * f4[q][3]);
        }
        evals += 4;
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
            radius = c.radius;
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
                    k[0] = level - 1, k[1] = i, k[2] = j, k[3] = level == 0 ? da : 2 * a + da,
                    k[4] = level == 0 ? db : 2 * b + db;
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
    Integrand in{env, lobe, s, p, 2 * s.nv * s.n - s.v, 1, 0, lobe.glossy()};
    in.w = 2 * lobe.alpha * std::max(s.nv, kMinWidthNv);
    in.cos_guard_w = std::cos(p.kappa * in.w);
    thread_local std::vector<EnvRegion> heap;
    heap.clear();
    const int top = env.top_level();
    for (int j = 0; j < env.height(top); ++j)
        for (int i = 0; i < env.width(top); ++i) {
            double e[3];
            if (in.estimate(top, i, j, 0, 0, e)) heap.push_back(in.region(top, i, j, 0, 0, e));
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
