// The windowed environment strategy (mc_window.h).
#include "renderers/reference/monte_carlo/mc_window.h"

#include <algorithm>
#include <cmath>

namespace iblcheck::reference {

bool pixel_view_cone(const Scene& scene, int W, int H, int x, int y, int sphere, PixelCone& cone) {
    const Sphere& sp = scene.spheres[size_t(sphere)];
    Vec3d ns[25], vs[25];
    int nh = 0;
    for (int gy = 0; gy < 5; ++gy)
        for (int gx = 0; gx < 5; ++gx) {
            Vec3f o, d;
            camera_ray(scene, W, H, x + (gx + 0.5) / 5, y + (gy + 0.5) / 5, o, d);
            double oc[3];
            double t = intersect_sphere(sp, o, d, oc);
            if (!std::isfinite(t)) continue;
            ns[nh] = normalize(Vec3d{oc[0] + t * d.x, oc[1] + t * d.y, oc[2] + t * d.z});
            vs[nh] = normalize(Vec3d{-d.x, -d.y, -d.z});
            ++nh;
        }
    if (nh == 0) {
        // Only sub-pixel slivers hit: take the pixel-centre ray's closest approach (a near-grazing normal).
        Vec3f o, d;
        camera_ray(scene, W, H, x + 0.5, y + 0.5, o, d);
        Vec3d dd = normalize(Vec3d{d.x, d.y, d.z});
        Vec3d c = Vec3d{sp.center.x - o.x, sp.center.y - o.y, sp.center.z - o.z};
        Vec3d p = dot(c, dd) * dd + (-1.0) * c; // closest point of the ray, relative to the centre
        if (dot(p, p) <= 0) return false;
        ns[0] = normalize(p), vs[0] = (-1.0) * dd, nh = 1;
    }
    Vec3d n0{0, 0, 0}, v0{0, 0, 0};
    for (int i = 0; i < nh; ++i) n0 = n0 + ns[i], v0 = v0 + vs[i];
    cone.n0 = normalize(n0), cone.v0 = normalize(v0);
    double min_cos = 1;
    for (int i = 0; i < nh; ++i) min_cos = std::min(min_cos, dot(ns[i], cone.n0));
    cone.spread = std::acos(std::clamp(min_cos, -1.0, 1.0)) * 1.1 + 0.01;
    if (nh < 25) cone.spread = std::max(cone.spread, 0.35); // partially covered: rays between the grid's reach the rim
    return true;
}

namespace {
// cos(max(0, a − δ)) from cos a, for δ given by its cos/sin: 1 inside δ.
double cos_minus(double ca, double cd, double sd) {
    if (ca >= cd) return 1.0;
    double sa = std::sqrt(std::max(0.0, 1 - ca * ca));
    return ca * cd + sa * sd;
}

// cos_minus(ca, cd, sd) clamped at 0, without its square root where the result is surely not positive:
// with 0 ≤ sa ≤ 1, sa·sd ≤ max(sd, 0) as computed too (rounding is monotone), so ca·cd + max(sd, 0) ≤ 0
// bounds the computed ca·cd + sa·sd. The same bits as cos_minus wherever it is positive; half the
// environment's cells are below a pixel's dilated horizon.
double cos_minus_positive(double ca, double cd, double sd) {
    if (ca < cd && ca * cd + std::max(sd, 0.0) <= 0) return 0.0;
    return std::max(cos_minus(ca, cd, sd), 0.0);
}

// The window's unnormalised terms per cell: factor = k̄_d·cos⁺(…) (diffuse), spec = S_c where the dilated
// cosine is positive (specular, before its normalisation); returns Σ S Ω, summed in cell order.
// The hemisphere window (the default) has S_c = 1 there, so its mirror-direction terms are not computed:
// they decide only the lobe window's D.
double window_cell_terms(const EnvDistribution& dist, const PixelCone& cone, Vec3d r0, double kd, double fbar, double alpha,
                         bool spec_lobe_window, std::vector<double>& factor, std::vector<double>& spec) {
    const int cells = dist.cells_x() * dist.cells_y();
    const Vec3d n0 = cone.n0;
    const double dp = cone.spread;
    // cos/sin of δ_p and 2δ_p, to add the cell radius δ_c (angles add: cos/sin of the sum).
    const double cdp = std::cos(dp), sdp = std::sin(dp), c2p = std::cos(2 * dp), s2p = std::sin(2 * dp);
    double spec_norm = 0;
    for (int c = 0; c < cells; ++c) {
        double K = 0, ks = 0;
        const double* cd = dist.cell_centre(c);
        const Vec3d dir{cd[0], cd[1], cd[2]};
        const double ccr = dist.cell_cos_radius(c), scr = dist.cell_sin_radius(c);
        const double rc = dist.cell_radius(c);
        // δ = δ_c + δ_p. The angle-sum cosines are those of δ only while δ < π; beyond, every direction is within δ.
        const double cd1 = ccr * cdp - scr * sdp, sd1 = scr * cdp + ccr * sdp;
        const double cb = rc + dp >= model::kPi ? 1.0 : cos_minus_positive(dot(dir, n0), cd1, sd1);
        if (cb > 0) { // else below the dilated horizon (the angle minus δ exceeds 90 degrees)
            K = kd * cb;
            if (fbar > 0) {
                ks = 1.0;
                if (spec_lobe_window) { // δ_c + 2δ_p about the mirror direction
                    const double cd2 = ccr * c2p - scr * s2p, sd2 = scr * c2p + ccr * s2p;
                    const double cg = rc + 2 * dp >= model::kPi ? 1.0 : cos_minus(dot(dir, r0), cd2, sd2);
                    ks = model::d_ggx(std::sqrt(std::max(0.0, 0.5 * (1 + cg))), alpha);
                }
                spec_norm += ks * dist.cell_solid_angle(c);
            }
        }
        factor[size_t(c)] = K;
        spec[size_t(c)] = ks;
    }
    return spec_norm;
}

// Rows cy0 .. cy0 + R − 1 of the window: K_c = diffuse + sn·specular into `factor`, and each row's running
// sums of K_c·W_c into its conditional CDF. A row's sums are a chain of dependent additions; R rows side
// by side keep the adder busy (the same sums in the same order as one row at a time, so the same bits).
template <int R>
void window_rows(const EnvDistribution& dist, int cy0, double sn, const std::vector<double>& spec, EnvWindow& win) {
    const int cw = dist.cells_x();
    double run[R];
    double* cond[R];
    for (int r = 0; r < R; ++r) {
        run[r] = 0;
        cond[r] = &win.conditional[size_t(cy0 + r) * size_t(cw + 1)];
        cond[r][0] = 0;
    }
    for (int cx = 0; cx < cw; ++cx)
        for (int r = 0; r < R; ++r) {
            const size_t c = size_t(cy0 + r) * size_t(cw) + size_t(cx);
            const double K = win.factor[c] + sn * spec[c];
            win.factor[c] = K;
            run[r] += K * dist.cell_mass(int(c));
            cond[r][cx + 1] = run[r];
        }
}
} // namespace

void build_window(const Scene& scene, int W, int H, int x, int y, int si, const MatConst& M, const EnvDistribution& dist,
                  bool spec_lobe_window, EnvWindow& win) {
    win.valid = false;
    if (dist.empty()) return;
    PixelCone cone;
    if (!pixel_view_cone(scene, W, H, x, y, si, cone)) return;
    const double nv = std::max(dot(cone.n0, cone.v0), kMinNdotV);
    const Vec3d r0 = 2 * nv * cone.n0 + (-1.0) * cone.v0;
    double kd = 0, fbar = 0;
    for (int i = 0; i < 3; ++i) kd += M.kd[i] / 3, fbar += (M.cont_spec ? model::f_schlick(M.f0[i], nv) : 0.0) / 3;
    const int cw = dist.cells_x(), ch = dist.cells_y();
    // Every entry is written below: sized, not cleared.
    win.marginal.resize(size_t(ch) + 1);
    win.conditional.resize(size_t(ch) * (cw + 1));
    win.factor.resize(size_t(cw) * ch);
    std::vector<double>& spec = win.spec_scratch;
    spec.resize(size_t(cw) * ch);
    const double spec_norm = window_cell_terms(dist, cone, r0, kd, fbar, M.alpha, spec_lobe_window, win.factor, spec);
    // The specular term normalised to carry F̄ over the sphere, like the diffuse term's π k̄_d.
    const double sn = spec_norm > 0 ? fbar / spec_norm : 0.0;
    int cy = 0;
    for (; cy + 4 <= ch; cy += 4) window_rows<4>(dist, cy, sn, spec, win);
    for (; cy < ch; ++cy) window_rows<1>(dist, cy, sn, spec, win);
    double total = 0;
    win.marginal[0] = 0;
    for (cy = 0; cy < ch; ++cy) {
        const double row = win.conditional[size_t(cy) * (cw + 1) + size_t(cw)];
        win.marginal[size_t(cy) + 1] = win.marginal[size_t(cy)] + row;
        total += row;
    }
    if (!(total > 0) || !std::isfinite(total)) return;
    for (double& f : win.factor) f /= total;
    win.valid = true;
}

double sample_env_window(const EnvDistribution& dist, const EnvWindow& win, double e0, double e1, double dw[3], double& u,
                         double& vv) {
    if (!win.valid) return dist.sample_uv(e0, e1, dw, u, vv);
    // Mixture: e1 < ε picks the global distribution, else the window (e1 rescaled, as for the lobes).
    double pg;
    int cell;
    if (e1 < kWindowDefensive) {
        pg = dist.sample_uv(e0, std::min(e1 / kWindowDefensive, 1.0 - 1e-16), dw, u, vv);
        cell = pg > 0 ? dist.cell_of_uv(u, vv) : 0;
    } else {
        double t = (e1 - kWindowDefensive) / (1 - kWindowDefensive);
        const int cw = dist.cells_x(), ch = dist.cells_y();
        // Cell row from the window's marginal, column from its conditional; the remainders place
        // the sample inside the cell (stratification carries over).
        double tr = std::min(t, 1.0 - 1e-16) * win.marginal[ch];
        int cy = search_cdf(win.marginal.data(), 0, ch, tr);
        double rr = std::clamp((tr - win.marginal[cy]) / (win.marginal[cy + 1] - win.marginal[cy]), 0.0, 1.0 - 1e-12);
        const double* cc = &win.conditional[size_t(cy) * (cw + 1)];
        double tc = e0 * cc[cw];
        int cx = search_cdf(cc, 0, cw, tc);
        double rc = std::clamp((tc - cc[cx]) / (cc[cx + 1] - cc[cx]), 0.0, 1.0 - 1e-12);
        cell = cy * cw + cx;
        pg = dist.sample_in_cell(cell, rc, rr, dw, u, vv);
    }
    return pg > 0 ? win.pdf_in_cell(cell, pg) : 0.0;
}

} // namespace iblcheck::reference
