// The Monte Carlo integrator (integrator=monte_carlo; the estimator is described in monte_carlo.h),
// moved unchanged from reference.cpp: it is kept as the independent check of the quadrature truth and
// for the nightly suite's sampled-reference row, not developed further (its long render function is
// as it was).
#include "renderers/reference/monte_carlo.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include <fmt/format.h>

#include "harness/common/vec3.h"
#include "renderers/material_model.h"

namespace iblcheck {

namespace {
using reference::EnvDistribution;
constexpr double kPi = model::kPi;
constexpr double kMirrorAlpha = 1e-4;
constexpr double kMinNdotV = 1e-5;

using V3 = Vec3d; // harness/common/vec3.h, with its operations

enum class Lobes { all, diffuse, specular };

// The equirect with environment.h's bilinear filter (sample_bilinear: texel centres at (i + 0.5)/W,
// u wraps, v clamps), addressed by uv so that the direction -> uv trigonometry is done once per
// direction and shared with the pdf lookup.
struct EnvImage {
    const float* data = nullptr;
    int W = 0, H = 0;
    size_t stride = 0; // floats per row
    explicit EnvImage(const cv::Mat& m) : data(m.ptr<float>(0)), W(m.cols), H(m.rows), stride(m.step1()) {}
    void lookup(double u, double v, double rgb[3]) const { bilinear_equirect(data, W, H, stride, u, v, rgb); }
};

struct Shader {
    const EnvImage& img;
    const EnvDistribution& dist;
    Lobes lobes;
    bool power = true;  // MIS heuristic: power (β = 2) or balance
    bool window = true; // env_sampling = window (EnvWindow) or global
};

// Per-sphere constants of the model.
struct MatConst {
    double alpha, a2, m, f0[3], kd[3], dw;
    bool want_diff, want_spec, mirror, cont_spec;
};
MatConst mat_const(const Material& mat, Lobes lobes) {
    MatConst c{};
    c.alpha = model::alpha_from_roughness(mat.roughness);
    c.a2 = c.alpha * c.alpha;
    c.m = mat.metallic;
    const double col[3] = {mat.base_color.x, mat.base_color.y, mat.base_color.z};
    c.want_diff = lobes != Lobes::specular && c.m < 1;
    c.want_spec = lobes != Lobes::diffuse;
    c.mirror = c.alpha < kMirrorAlpha;
    c.cont_spec = c.want_spec && !c.mirror;
    c.dw = 0;
    for (int i = 0; i < 3; ++i) {
        c.f0[i] = model::f0_from(col[i], c.m);
        c.kd[i] = c.want_diff ? (1 - c.m) * col[i] / kPi : 0.0;
        c.dw += (1 - c.m) * col[i];
    }
    return c;
}

// The environment strategy's distribution for one pixel and sphere: the environment distribution
// (∝ luminance) reweighted per coarse cell by a window K_c that approximates the rest of the integrand,
// f·(n·l), over the directions the pixel's hits can see:
//   K_c = k̄_d · cos⁺(∠(c, n₀) − δ_c − δ_p)          diffuse: Lambert's cosine, dilated
//       + F̄ · S_c / Σ S Ω   where cos⁺(…) > 0       specular, normalised to carry F̄ over the sphere
//   S_c = 1 (env_window = hemisphere, default)  or  D(cos(γ/2)), γ = max(0, ∠(c, r₀) − δ_c − 2δ_p) (lobe)
// with n₀, r₀ the normal and mirror direction at the centre of the pixel's hits on the sphere, δ_p the
// largest angle from n₀ to the normals seen in the pixel (×1.1 + 0.01), δ_c the cell's angular radius,
// k̄_d and F̄ the channel means of the Lambert term and of Schlick at n₀·v, Ω the cells' solid angles.
// ∫ k̄_d cos dl = π k̄_d is the diffuse albedo and the specular term integrates to F̄, so the two terms
// carry the lobes' relative energy. (Without the normalisation, the dilated D plateau held ~50x the
// lobe's energy and starved the diffuse lobe of dielectrics.)
// Sampling: a cell with probability P_c = K_c W_c / Σ K W (W_c: the cell's share of the luminance),
// then a pixel of it from the global distribution, so pdf_window(ω) = pdf(ω) · K_c / Σ K W. It is a
// mixture with the global distribution, weight ε = 0.1 (defensive sampling, Hesterberg 1995): every
// direction with radiance keeps a non-zero env pdf (a 5e4 sun outside a badly estimated window is
// still sampled; MIS with the BRDF strategy keeps the estimator unbiased whatever the window is, the
// window only decides how well the product L·f·cos is followed). The window is a deterministic
// function of the pixel and sphere, the same for every lighting seed.
// Measured (noise floor between seeds: mean FLIP / relative RMSE, roughness_sweep 528x96, 1024 spp):
//   studio:  global distribution 0.0117 / 1.65 %; window (64x32 cells, unnormalised lobe) 0.0099 / 1.20 %;
//            + silhouette boost 0.0073 / 0.90 %; 128x64 cells 0.0067 / 0.83 %; normalised lobe
//            0.0060 / 0.72 %; normalised hemisphere 0.0060 / 0.89 %; lobe + mis_compensation 1:
//            0.0056 / 0.68 %
//   sunrise: normalised lobe 0.0083 / 0.61 %; hemisphere 0.0084 / 0.62 %; lobe + mis_compensation 1:
//            0.0107 / 0.85 % (the compensated strategy leaves the bright sky to cosine sampling)
//   furnace (constant:1, 4096 spp): lobe 0.15 % rel. RMSE; hemisphere 0.046 %: in a constant
//   environment the lobe window competes with the exact GGX sampling instead of helping it (a metal
//   r = 0.25 furnace sphere: 0.31 % vs 0.07 % for the global distribution), the hemisphere does not.
//   Hence hemisphere by default: the same FLIP, the only criterion not met with margin, and no
//   pathological case. A Lambert sphere (lobes=diffuse, studio, 128 px, 256 spp): 2.36 % -> 1.04 %.
// (Product sampling by per-region light distributions: e.g. Conty Estevez & Kulla 2018, "Importance
// Sampling of Many Lights with Adaptive Tree Splitting"; Clarberg et al. 2005 for the product of
// environment and BRDF.)
constexpr double kWindowDefensive = 0.1;
struct EnvWindow {
    bool valid = false;
    std::vector<double> marginal;    // ch + 1
    std::vector<double> conditional; // ch * (cw + 1)
    std::vector<double> factor;      // cw * ch: K_c / Σ K W (pdf_window = pdf · factor)
    std::vector<double> spec_scratch;
    double pdf(const EnvDistribution& d, double u, double v, double pdf_global) const {
        if (!valid) return pdf_global;
        return pdf_in_cell(d.cell_of_uv(u, v), pdf_global);
    }
    // The same where the direction's cell c is already known (a sample drawn from the window).
    double pdf_in_cell(int c, double pdf_global) const {
        return pdf_global * ((1 - kWindowDefensive) * factor[size_t(c)] + kWindowDefensive);
    }
};

// Per-pixel scramble seeds of the lighting dimensions.
struct LightSeeds {
    uint32_t brdf, select, env;
};

// Shades one camera sub-sample: world normal n, direction to the viewer v; adds into out[3].
void shade(const Shader& S, const MatConst& M, const EnvWindow& win, V3 n, V3 v, const LightSeeds& seeds, uint32_t k,
           double out[3], long& fetches) {
    // Local frame (Duff et al. 2017).
    double sign = std::copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
    V3 t{1 + sign * n.x * n.x * a, sign * b, -sign * n.x};
    V3 bt{b, sign + n.y * n.y * a, -n.y};
    auto to_world = [&](V3 l) { return l.x * t + l.y * bt + l.z * n; };
    V3 vl{dot(v, t), dot(v, bt), dot(v, n)};
    if (vl.z < kMinNdotV) {
        double s = std::sqrt(std::max(0.0, 1 - kMinNdotV * kMinNdotV) / std::max(1e-300, vl.x * vl.x + vl.y * vl.y));
        vl = V3{vl.x * s, vl.y * s, kMinNdotV};
        if (!std::isfinite(s)) vl = V3{std::sqrt(1 - kMinNdotV * kMinNdotV), 0, kMinNdotV};
    }
    const double nv = vl.z;
    const double alpha = M.alpha, a2 = M.a2;

    if (M.want_spec && M.mirror) {
        // Delta lobe: ∫ D V F (n·l) L dl -> F(v·n) L(reflect(v)) (G2 = 1 at α = 0).
        V3 r = to_world(V3{-vl.x, -vl.y, vl.z});
        double rd[3] = {r.x, r.y, r.z}, u, vv, L[3];
        S.dist.to_uv(rd, u, vv);
        S.img.lookup(u, vv, L);
        ++fetches;
        for (int i = 0; i < 3; ++i) out[i] += model::f_schlick(M.f0[i], nv) * L[i];
    }
    const bool want_diff = M.want_diff, cont_spec = M.cont_spec;
    if (!want_diff && !cont_spec) return;

    double p_s;
    if (!want_diff)
        p_s = 1;
    else if (!cont_spec)
        p_s = 0;
    else {
        double sw = 0;
        for (int i = 0; i < 3; ++i) sw += model::f_schlick(M.f0[i], nv);
        p_s = std::clamp(sw / (sw + M.dw), 0.1, 0.9);
    }
    const double lambda_v = std::sqrt(a2 + (1 - a2) * nv * nv);
    const double vndf_norm = 1.0 / (2 * (nv + lambda_v));
    const double gv_term = std::sqrt(nv * nv * (1.0 - a2) + a2); // for V (material_model.h)

    // f(l)·(n·l) per channel for local l (n·l > 0), and the BRDF-strategy pdf, sharing h.
    auto eval_pdf = [&](V3 l, double fc[3]) {
        double nl = l.z;
        for (int i = 0; i < 3; ++i) fc[i] = M.kd[i] * nl;
        double p = (1 - p_s) * nl / kPi;
        if (cont_spec) {
            V3 h = normalize(l + vl);
            double nh = h.z, vh = dot(vl, h);
            double d = model::d_ggx(nh, alpha);
            // V = 0.5 / (n·l √(n·v²(1−α²)+α²) + n·v √(n·l²(1−α²)+α²)), exactly material_model.h's.
            double vis = 0.5 / (nl * gv_term + nv * std::sqrt(nl * nl * (1.0 - a2) + a2));
            double dv = d * vis * nl;
            for (int i = 0; i < 3; ++i) fc[i] += dv * model::f_schlick(M.f0[i], vh);
            // VNDF: D(h) G1(v) max(0, v·h) / (n·v) / (4 v·h) = D / (2 (n·v + Λ_v))
            p += p_s * d * vndf_norm;
        }
        return p;
    };

    double u0, u1;
    reference::sobol_owen_2d(k, seeds.brdf, u0, u1);

    // (a) BRDF sampling. The lobe is chosen by splitting u1 at p_s and rescaling the chosen part to
    // [0,1) (uniform given the choice, so exactly the mixture pdf below): each lobe gets a stratified
    // sub-pattern of the Sobol points, where a separate selection number would give each a random subset.
    V3 l;
    const bool pick_spec = u1 < p_s;
    u1 = pick_spec ? u1 / p_s : (u1 - p_s) / (1 - p_s);
    u1 = std::min(u1, 1.0 - 1e-16);
    if (pick_spec) {
        // Heitz 2018 VNDF sampling.
        V3 vh = normalize(V3{alpha * vl.x, alpha * vl.y, vl.z});
        double lensq = vh.x * vh.x + vh.y * vh.y;
        V3 T1 = lensq > 0 ? (1.0 / std::sqrt(lensq)) * V3{-vh.y, vh.x, 0} : V3{1, 0, 0};
        V3 T2 = cross(vh, T1);
        double r = std::sqrt(u0), phi = 2 * kPi * u1;
        double t1 = r * std::cos(phi), t2 = r * std::sin(phi);
        double s = 0.5 * (1 + vh.z);
        t2 = (1 - s) * std::sqrt(std::max(0.0, 1 - t1 * t1)) + s * t2;
        V3 nh = t1 * T1 + t2 * T2 + std::sqrt(std::max(0.0, 1 - t1 * t1 - t2 * t2)) * vh;
        V3 h = normalize(V3{alpha * nh.x, alpha * nh.y, std::max(0.0, nh.z)});
        l = 2 * dot(vl, h) * h + (-1.0) * vl;
    } else {
        double r = std::sqrt(u0), phi = 2 * kPi * u1;
        l = V3{r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1 - u0))};
    }
    if (l.z > 0) {
        double fc[3];
        double pb = eval_pdf(l, fc);
        if (pb > 0) {
            V3 lw = to_world(l);
            double lwd[3] = {lw.x, lw.y, lw.z}, u, vv, L[3];
            S.dist.to_uv(lwd, u, vv);
            double pe = win.pdf(S.dist, u, vv, S.dist.pdf_uv(u, vv));
            double w = S.power ? pb / (pb + pe * (pe / pb)) : pb / (pb + pe);
            S.img.lookup(u, vv, L);
            ++fetches;
            for (int i = 0; i < 3; ++i) out[i] += fc[i] * L[i] * (w / pb);
        }
    }

    // (b) Environment sampling.
    if (!S.dist.empty()) {
        double e0, e1, dw[3], u, vv, pe = 0;
        reference::sobol_owen_2d(k, seeds.env, e0, e1);
        if (!win.valid)
            pe = S.dist.sample_uv(e0, e1, dw, u, vv);
        else {
            // Mixture: e1 < ε picks the global distribution, else the window (e1 rescaled, as for the lobes).
            double pg;
            int cell;
            if (e1 < kWindowDefensive) {
                pg = S.dist.sample_uv(e0, std::min(e1 / kWindowDefensive, 1.0 - 1e-16), dw, u, vv);
                cell = pg > 0 ? S.dist.cell_of_uv(u, vv) : 0;
            } else {
                double t = (e1 - kWindowDefensive) / (1 - kWindowDefensive);
                const int cw = S.dist.cells_x(), ch = S.dist.cells_y();
                // Cell row from the window's marginal, column from its conditional; the remainders place
                // the sample inside the cell (stratification carries over).
                double tr = std::min(t, 1.0 - 1e-16) * win.marginal[ch];
                int cy = reference::search_cdf(win.marginal.data(), 0, ch, tr);
                double rr = std::clamp((tr - win.marginal[cy]) / (win.marginal[cy + 1] - win.marginal[cy]), 0.0, 1.0 - 1e-12);
                const double* cc = &win.conditional[size_t(cy) * (cw + 1)];
                double tc = e0 * cc[cw];
                int cx = reference::search_cdf(cc, 0, cw, tc);
                double rc = std::clamp((tc - cc[cx]) / (cc[cx + 1] - cc[cx]), 0.0, 1.0 - 1e-12);
                cell = cy * cw + cx;
                pg = S.dist.sample_in_cell(cell, rc, rr, dw, u, vv);
            }
            pe = pg > 0 ? win.pdf_in_cell(cell, pg) : 0.0;
        }
        if (pe > 0) {
            V3 lw{dw[0], dw[1], dw[2]};
            V3 ll{dot(lw, t), dot(lw, bt), dot(lw, n)};
            if (ll.z > 0) {
                double fc[3], L[3];
                double pb = eval_pdf(ll, fc);
                double w = S.power ? pe * pe / (pe * pe + pb * pb) : pe / (pe + pb);
                S.img.lookup(u, vv, L);
                ++fetches;
                for (int i = 0; i < 3; ++i) out[i] += fc[i] * L[i] * (w / pe);
            }
        }
    }
}

std::string estimator_description(bool window, bool lobe_window, double compensation, int silhouette_boost) {
    std::string env = std::string("environment sampling [piecewise-constant equirect distribution ~ ") +
                      (compensation > 0 ? "max(0, 3x3-max luminance - " + fmt::format("{:g}", compensation) +
                                              " x mean luminance) (MIS compensation, Karlik et al. 2019)"
                                        : std::string("3x3-max luminance")) +
                      " * solid angle, guide-table CDF inversion";
    if (window)
        env += std::string("; per pixel and sphere reweighted by 128x64 cells with a window ~ dilated cosine (diffuse) + ") +
               (lobe_window ? "GGX D about the mirror direction" : "flat hemisphere") +
               " (specular), mixed with 10 % of the unwindowed distribution";
    env += "]";
    return "sub-pixel positions: an Owen-scrambled Sobol pattern per pixel keyed by pixel_pattern (not by the "
           "lighting seed); lighting per position: MIS (power heuristic, 1 sample each) of "
           "BRDF sampling [mixture of GGX VNDF (Heitz 2018) with p_s = F/(F+diffuse) clamped to [0.1,0.9], and "
           "cosine hemisphere] and " +
           env + ", whole BRDF per sample; adaptive lighting-sample counts from a discarded pilot, silhouette pixels at least " +
           std::to_string(silhouette_boost) +
           "x the mean; alpha < 1e-4 treated as a mirror delta F(n.v) L(reflect); bilinear env lookups; no "
           "inter-sphere occlusion";
}

// Spheres that any ray through pixel (x, y) can hit (conservative), so the per-sample intersection
// loop skips the others. Orthographic: distance of the centre from the pixel-centre ray ≤ radius +
// half the pixel diagonal. Perspective: angle between the centre ray and the sphere ≤ its angular
// radius + the largest centre-to-corner ray angle.
void pixel_candidates(const Scene& scene, int W, int H, int x, int y, std::vector<int>& out) {
    out.clear();
    Vec3f oc, dc;
    camera_ray(scene, W, H, x + 0.5, y + 0.5, oc, dc);
    V3 o{oc.x, oc.y, oc.z}, d = normalize(V3{dc.x, dc.y, dc.z});
    double slack = 0;
    for (int c = 0; c < 4; ++c) {
        Vec3f o2, d2;
        camera_ray(scene, W, H, x + (c & 1), y + (c >> 1), o2, d2);
        if (scene.camera.orthographic) {
            V3 dd = V3{o2.x, o2.y, o2.z} - o;
            slack = std::max(slack, std::sqrt(dot(dd, dd)));
        } else {
            double cs = std::clamp(dot(d, normalize(V3{d2.x, d2.y, d2.z})), -1.0, 1.0);
            slack = std::max(slack, std::acos(cs));
        }
    }
    slack = slack * 1.01 + 1e-5;
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        const Sphere& s = scene.spheres[i];
        V3 c = V3{s.center.x, s.center.y, s.center.z} - o;
        double r = double(s.radius) * 1.0001 + 1e-6, along = dot(c, d), cc = dot(c, c);
        bool cand;
        if (scene.camera.orthographic) {
            double dist = std::sqrt(std::max(0.0, cc - along * along));
            cand = dist <= r + slack;
        } else {
            double D = std::sqrt(cc);
            if (D <= r)
                cand = true;
            else {
                double ang = std::acos(std::clamp(along / D, -1.0, 1.0));
                cand = ang <= std::asin(std::min(1.0, r / D)) + slack;
            }
        }
        if (cand) out.push_back(int(i));
    }
}

// Nearest hit among the candidate spheres: the arithmetic of scene.cpp's intersect().
bool intersect_candidates(const Scene& scene, const std::vector<int>& cand, Vec3f origin, Vec3f dir, int& sphere, V3& normal) {
    double best_t = INFINITY;
    sphere = -1;
    for (int i : cand) {
        double oc[3];
        double t = intersect_sphere(scene.spheres[i], origin, dir, oc);
        if (t >= best_t) continue;
        best_t = t;
        sphere = i;
        double px = oc[0] + t * dir.x, py = oc[1] + t * dir.y, pz = oc[2] + t * dir.z;
        normal = V3{px, py, pz};
    }
    if (sphere < 0) return false;
    // Same rounding as intersect(): a float unit normal.
    double inv = 1.0 / std::sqrt(dot(normal, normal));
    normal = V3{double(float(normal.x * inv)), double(float(normal.y * inv)), double(float(normal.z * inv))};
    normal = normalize(normal);
    return true;
}

// Builds the window of pixel (x, y) for sphere `si` (EnvWindow above). n₀, δ_p from a 5x5 grid of rays
// over the pixel: the mean of the hit normals, and the largest angle from it (×1.1 + 0.01); where some
// rays miss, the grid's hits alone (silhouette pixels: their hits are near-grazing, the spread is wide).
void build_window(const Scene& scene, int W, int H, int x, int y, int si, const MatConst& M, const EnvDistribution& dist,
                  bool spec_lobe_window, EnvWindow& win) {
    win.valid = false;
    if (dist.empty()) return;
    const Sphere& sp = scene.spheres[size_t(si)];
    V3 ns[25], vs[25];
    int nh = 0;
    for (int gy = 0; gy < 5; ++gy)
        for (int gx = 0; gx < 5; ++gx) {
            Vec3f o, d;
            camera_ray(scene, W, H, x + (gx + 0.5) / 5, y + (gy + 0.5) / 5, o, d);
            double oc[3];
            double t = intersect_sphere(sp, o, d, oc);
            if (!std::isfinite(t)) continue;
            ns[nh] = normalize(V3{oc[0] + t * d.x, oc[1] + t * d.y, oc[2] + t * d.z});
            vs[nh] = normalize(V3{-d.x, -d.y, -d.z});
            ++nh;
        }
    if (nh == 0) {
        // Only sub-pixel slivers hit: take the pixel-centre ray's closest approach (a near-grazing normal).
        Vec3f o, d;
        camera_ray(scene, W, H, x + 0.5, y + 0.5, o, d);
        V3 dd = normalize(V3{d.x, d.y, d.z});
        V3 c = V3{sp.center.x - o.x, sp.center.y - o.y, sp.center.z - o.z};
        V3 p = dot(c, dd) * dd + (-1.0) * c; // closest point of the ray, relative to the centre
        if (dot(p, p) <= 0) return;
        ns[0] = normalize(p), vs[0] = (-1.0) * dd, nh = 1;
    }
    V3 n0{0, 0, 0}, v0{0, 0, 0};
    for (int i = 0; i < nh; ++i) n0 = n0 + ns[i], v0 = v0 + vs[i];
    n0 = normalize(n0), v0 = normalize(v0);
    double min_cos = 1;
    for (int i = 0; i < nh; ++i) min_cos = std::min(min_cos, dot(ns[i], n0));
    double dp = std::acos(std::clamp(min_cos, -1.0, 1.0)) * 1.1 + 0.01;
    if (nh < 25) dp = std::max(dp, 0.35); // partially covered: rays between the grid's reach the rim
    const double nv = std::max(dot(n0, v0), kMinNdotV);
    V3 r0 = 2 * nv * n0 + (-1.0) * v0;
    double kd = 0, fbar = 0;
    for (int i = 0; i < 3; ++i) kd += M.kd[i] / 3, fbar += (M.cont_spec ? model::f_schlick(M.f0[i], nv) : 0.0) / 3;
    const int cw = dist.cells_x(), ch = dist.cells_y();
    win.marginal.assign(size_t(ch) + 1, 0.0);
    win.conditional.assign(size_t(ch) * (cw + 1), 0.0);
    win.factor.assign(size_t(cw) * ch, 0.0);
    // cos(max(0, a − δ)) from cos a, for δ = cell radius + spread (cos/sin precomputed): 1 inside δ.
    const double cdp = std::cos(dp), sdp = std::sin(dp), c2p = std::cos(2 * dp), s2p = std::sin(2 * dp);
    auto cos_minus = [](double ca, double cd, double sd) {
        if (ca >= cd) return 1.0;
        double sa = std::sqrt(std::max(0.0, 1 - ca * ca));
        return ca * cd + sa * sd;
    };
    double total = 0, spec_norm = 0;
    std::vector<double>& spec = win.spec_scratch;
    spec.assign(size_t(cw) * ch, 0.0);
    for (int cy = 0; cy < ch; ++cy) {
        for (int cx = 0; cx < cw; ++cx) {
            const int c = cy * cw + cx;
            double K = 0, ks = 0;
            {
                const double* cd = dist.cell_centre(c);
                const V3 dir{cd[0], cd[1], cd[2]};
                const double ccr = dist.cell_cos_radius(c), scr = dist.cell_sin_radius(c);
                // δ = δ_c + δ_p (angles add: cos/sin of the sum), and δ_c + 2δ_p for the mirror direction.
                const double cd1 = ccr * cdp - scr * sdp, sd1 = scr * cdp + ccr * sdp;
                const double cd2 = ccr * c2p - scr * s2p, sd2 = scr * c2p + ccr * s2p;
                const double rc = dist.cell_radius(c);
                // The angle-sum cosines are those of δ only while δ < π; beyond, every direction is within δ.
                const double cb = rc + dp >= kPi ? 1.0 : cos_minus(dot(dir, n0), cd1, sd1);
                if (cb > 0) { // else below the dilated horizon (the angle minus δ exceeds 90 degrees)
                    K = kd * cb;
                    if (fbar > 0) {
                        double cg = rc + 2 * dp >= kPi ? 1.0 : cos_minus(dot(dir, r0), cd2, sd2);
                        double ch_half = std::sqrt(std::max(0.0, 0.5 * (1 + cg)));
                        ks = spec_lobe_window ? model::d_ggx(ch_half, M.alpha) : 1.0;
                        spec_norm += ks * dist.cell_solid_angle(c);
                    }
                }
            }
            win.factor[size_t(c)] = K;
            spec[size_t(c)] = ks;
        }
    }
    // The specular term normalised to carry F̄ over the sphere, like the diffuse term's π k̄_d.
    const double sn = spec_norm > 0 ? fbar / spec_norm : 0.0;
    for (int cy = 0; cy < ch; ++cy) {
        double* cond = &win.conditional[size_t(cy) * (cw + 1)];
        for (int cx = 0; cx < cw; ++cx) {
            const int c = cy * cw + cx;
            double K = win.factor[size_t(c)] + sn * spec[size_t(c)];
            win.factor[size_t(c)] = K;
            cond[cx + 1] = cond[cx] + K * dist.cell_mass(c);
        }
        win.marginal[size_t(cy) + 1] = win.marginal[size_t(cy)] + cond[cw];
        total += cond[cw];
    }
    if (!(total > 0) || !std::isfinite(total)) return;
    for (double& f : win.factor) f /= total;
    win.valid = true;
}

} // namespace

ReferenceRender render_reference_full(const TestSpec& spec, const Environment* env_in) {
    auto t0 = std::chrono::steady_clock::now();
    Scene scene = build_scene(spec.scene, spec.options);
    const OptionMap& o = spec.options;
    int spp = o.get_int("spp", kReferenceDefaultSpp);
    int seed = o.get_int("seed", 0);
    int pattern = o.get_int("pixel_pattern", 0);
    const bool adaptive = o.get_int("adaptive", 1) != 0;
    const int adaptive_cap = o.get_int("adaptive_cap", 16);
    const int silhouette_boost = o.get_int("silhouette_boost", 16);
    const int positions = std::clamp(o.get_int("positions", std::max(1, spp / 4)), 1, std::max(1, spp));
    int threads = o.get_int("threads", 0);
    double rot = o.get_double("env_rotation", 0.0);
    std::string lobes_s = o.get_choice("lobes", "all", {"all", "diffuse", "specular"});
    std::string mis = o.get_choice("mis", "power", {"power", "balance"});
    std::string env_sampling = o.get_choice("env_sampling", "window", {"window", "global"});
    std::string env_window = o.get_choice("env_window", "hemisphere", {"hemisphere", "lobe"});
    const double mis_compensation = o.get_double("mis_compensation", 0.0);
    if (mis_compensation < 0) throw UsageError("option 'mis_compensation': must be >= 0");
    if (spp < 1) throw UsageError("option 'spp': must be >= 1");
    if (threads < 0) throw UsageError("option 'threads': must be >= 0");
    if (silhouette_boost < 1) throw UsageError("option 'silhouette_boost': must be >= 1");
    Lobes lobes = lobes_s == "diffuse" ? Lobes::diffuse : lobes_s == "specular" ? Lobes::specular : Lobes::all;

    Environment env = env_in ? *env_in : load_environment(spec.env);
    if (o.has("env_rotation")) env.rotation_deg = float(rot);
    EnvDistribution dist(env, mis_compensation);
    cv::Mat equirect = env.equirect.isContinuous() ? env.equirect : env.equirect.clone();
    EnvImage img(equirect);

    const int W = spec.width > 0 ? spec.width : scene.width;
    const int H = spec.height > 0 ? spec.height : scene.height;
    if (threads == 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    threads = std::min(threads, H);

    cv::Mat image(H, W, CV_32FC3, cv::Scalar(0, 0, 0));
    cv::Mat coverage(H, W, CV_32FC1, cv::Scalar(0));
    std::vector<long> row_fetches(H, 0);
    Shader S{img, dist, lobes, mis == "power", env_sampling == "window"};
    std::vector<MatConst> mats;
    for (const auto& sp : scene.spheres) mats.push_back(mat_const(sp.material, lobes));
    const uint32_t seed_hash = reference::hash_u32(uint32_t(seed) * 0x9e3779b9u + 0x85ebca6bu);
    // The sub-pixel pattern has its own key: renders with different lighting seeds integrate the
    // pixel footprint with the same points, so their difference is lighting noise only (reference.h).
    const uint32_t pattern_hash = reference::hash_u32(uint32_t(pattern) * 0x2545f491u + 0x6a09e667u);

    // One pixel: P sub-pixel positions from pattern key `pat` (the same for every lighting seed); at
    // each position that hits a sphere, M lighting samples (Sobol indices k·M .. k·M + M − 1 of the
    // pixel's lighting sequence, key `pix_seed`). Returns the pixel mean, the coverage, and (for the
    // pilot) the mean and sample variance of the per-lighting-sample luminance over the hits.
    struct PixelOut {
        double rgb[3] = {0, 0, 0};
        double coverage = 0, lum_mean = 0, lum_var = 0;
    };
    auto render_pixel = [&](int x, int y, int P, int M, uint32_t pat, uint32_t pix_seed, const std::vector<int>& cand,
                            long& fetches) {
        PixelOut po;
        const LightSeeds seeds{reference::hash_u32(pix_seed ^ 0x68bc21ebu), reference::hash_u32(pix_seed ^ 0x02e5be93u),
                               reference::hash_u32(pix_seed ^ 0x7b3f9a11u)};
        double acc[3] = {0, 0, 0}, s1 = 0, s2 = 0;
        int hits = 0;
        std::vector<EnvWindow> wins(cand.size());
        std::vector<char> win_built(cand.size(), 0);
        if (!cand.empty())
            for (int k = 0; k < P; ++k) {
                double sx, sy;
                reference::sobol_owen_2d(uint32_t(k), pat, sx, sy);
                Vec3f o3, d3;
                camera_ray(scene, W, H, x + sx, y + sy, o3, d3);
                int sph;
                V3 nrm;
                if (!intersect_candidates(scene, cand, o3, d3, sph, nrm)) continue;
                ++hits;
                V3 v = normalize(V3{-d3.x, -d3.y, -d3.z});
                // This sphere's window, built at its first hit in the pixel.
                size_t ci = size_t(std::find(cand.begin(), cand.end(), sph) - cand.begin());
                if (S.window && !win_built[ci]) {
                    build_window(scene, W, H, x, y, sph, mats[size_t(sph)], dist, env_window == "lobe", wins[ci]);
                    win_built[ci] = 1;
                }
                double pos[3] = {0, 0, 0};
                for (int m = 0; m < M; ++m) {
                    double one[3] = {0, 0, 0};
                    shade(S, mats[sph], wins[ci], nrm, v, seeds, uint32_t(k) * uint32_t(M) + uint32_t(m), one, fetches);
                    double yl = 0.2126 * one[0] + 0.7152 * one[1] + 0.0722 * one[2];
                    s1 += yl, s2 += yl * yl;
                    for (int i = 0; i < 3; ++i) pos[i] += one[i];
                }
                for (int i = 0; i < 3; ++i) acc[i] += pos[i] / M;
            }
        for (int i = 0; i < 3; ++i) po.rgb[i] = acc[i] / P;
        po.coverage = double(hits) / P;
        const long ns = long(hits) * M;
        po.lum_mean = ns ? s1 / ns : 0.0;
        po.lum_var = ns > 1 ? std::max(0.0, (s2 - s1 * s1 / ns) / (ns - 1)) : 0.0;
        return po;
    };
    auto parallel_rows = [&](auto&& row_fn) {
        std::atomic<int> next_row{0};
        auto worker = [&] {
            std::vector<int> cand;
            for (int y; (y = next_row.fetch_add(1)) < H;) row_fn(y, cand);
        };
        std::vector<std::thread> pool;
        for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
        worker();
        for (auto& th : pool) th.join();
    };
    auto t1 = std::chrono::steady_clock::now();

    // Lighting samples per hit position. adaptive: a pilot pass (its own lighting keys, independent of
    // the main pass's; pilot_positions of the pattern × 2 lighting samples) estimates each pixel's
    // σ_L (per-lighting-sample standard deviation of the luminance over its hits) and its value μ; the
    // pixel's relative variance is ≈ c·σ_L²/(P·M·(μ² + 0.01)) at cost c·P·M (c = coverage), so counts
    // M ∝ σ_L/√(μ² + 0.01) (3x3 max, so a ring of noisy pixels is covered whole) minimise the summed
    // relative variance for the same work. Clamped to [M̄/4, adaptive_cap·M̄], M̄ = spp/P.
    // Silhouette pixels (pilot coverage < 1) get at least silhouette_boost·M̄ (default 16): the mean FLIP
    // between seeds is not the relative MSE — FLIP's edge detector turns a silhouette pixel's noise into
    // error on both sides of the edge, background included. Measured on the studio sweep at 1024 spp:
    // the silhouette ring (partially covered pixels and the background next to them) was half the mean
    // FLIP (0.0099); raising adaptive_cap to 64 changed nothing (these pixels' σ_L/μ is not larger
    // than their neighbours'), the boost took the FLIP to 0.0073 for 1.55x the time — better than the
    // ~0.0083 that 1.55x the samples everywhere would give.
    // The pilot's samples are then discarded: the counts depend on the pilot only, the main samples
    // are independent of it, so each pixel's estimate stays unbiased.
    const int m_mean = std::max(1, int(std::lround(double(spp) / positions)));
    std::vector<int> counts(size_t(W) * H, m_mean);
    long pilot_samples = 0;
    if (adaptive) {
        std::vector<double> r(size_t(W) * H, -1.0);
        std::vector<char> partial(size_t(W) * H, 0);
        const uint32_t pilot_hash = reference::hash_u32(seed_hash ^ 0x3c6ef372u);
        const int pilot_pos = std::min(positions, 32);
        std::atomic<long> pilot_n{0};
        parallel_rows([&](int y, std::vector<int>& cand) {
            long f = 0;
            for (int x = 0; x < W; ++x) {
                const uint32_t pix = reference::hash_u32(uint32_t(y) * uint32_t(W) + uint32_t(x));
                pixel_candidates(scene, W, H, x, y, cand);
                if (cand.empty()) continue;
                PixelOut po = render_pixel(x, y, pilot_pos, 2, reference::hash_u32(pattern_hash ^ pix),
                                           reference::hash_u32(pilot_hash ^ pix), cand, f);
                double mu = po.coverage * po.lum_mean;
                r[size_t(y) * W + x] = std::sqrt(po.lum_var) / std::sqrt(mu * mu + 0.01);
                if (po.coverage < 1) partial[size_t(y) * W + x] = 1; // silhouette (or a sliver the pilot missed)
                pilot_n += long(std::lround(po.coverage * pilot_pos)) * 2;
            }
        });
        pilot_samples = pilot_n;
        std::vector<double> rm(r.size(), -1.0);
        double sum = 0;
        long cnt = 0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                if (r[size_t(y) * W + x] < 0) continue;
                double m = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        int yy = y + dy, xx = x + dx;
                        if (yy >= 0 && yy < H && xx >= 0 && xx < W) m = std::max(m, r[size_t(yy) * W + xx]);
                    }
                rm[size_t(y) * W + x] = m;
                if (m > 0) sum += m, ++cnt;
            }
        double mean_r = cnt ? sum / cnt : 0;
        for (size_t i = 0; i < rm.size(); ++i) {
            if (rm[i] < 0) continue; // no sphere can be hit: the count is irrelevant
            double c = mean_r > 0 ? m_mean * rm[i] / mean_r : m_mean;
            counts[i] = int(std::clamp(std::lround(c), long(std::max(1, m_mean / 4)), long(adaptive_cap) * m_mean));
            if (partial[i]) counts[i] = std::max(counts[i], silhouette_boost * m_mean);
        }
    }

    parallel_rows([&](int y, std::vector<int>& cand) {
        long fetches = 0;
        for (int x = 0; x < W; ++x) {
            const uint32_t pix = reference::hash_u32(uint32_t(y) * uint32_t(W) + uint32_t(x));
            const uint32_t pix_seed = reference::hash_u32(seed_hash ^ pix);
            const uint32_t pat_seed = reference::hash_u32(pattern_hash ^ pix);
            pixel_candidates(scene, W, H, x, y, cand);
            PixelOut po = render_pixel(x, y, positions, counts[size_t(y) * W + x], pat_seed, pix_seed, cand, fetches);
            auto& px = image.at<cv::Vec3f>(y, x);
            for (int i = 0; i < 3; ++i) px[i] = float(po.rgb[i]);
            coverage.at<float>(y, x) = float(po.coverage);
        }
        row_fetches[y] = fetches;
    });
    auto t2 = std::chrono::steady_clock::now();
    long main_samples = 0, covered = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            if (coverage.at<float>(y, x) > 0)
                main_samples += long(std::lround(coverage.at<float>(y, x) * positions)) * counts[size_t(y) * W + x], ++covered;

    long total_fetches = 0;
    for (long f : row_fetches) total_fetches += f;

    ReferenceRender out;
    out.coverage = coverage;
    RenderResult& r = out.result;
    r.image = image;
    double ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
    r.timings.push_back({"reference_cpu", ms, false, false});
    r.texture_fetches_per_pixel = double(total_fetches) / (double(W) * H);
    double total_s = std::chrono::duration<double>(t2 - t0).count();
    r.provenance = {
        {"method", "reference"},
        {"scene", spec.scene},
        {"options", spec.options.canonical()},
        {"width", W},
        {"height", H},
        {"spp", spp},
        {"seed", seed},
        {"pixel_pattern", pattern},
        {"adaptive", adaptive},
        {"positions", positions},
        {"lighting_samples_per_covered_pixel", covered ? double(main_samples) / double(covered) : 0.0},
        {"pilot_samples", pilot_samples},
        {"threads", threads},
        {"lobes", lobes_s},
        {"mis", mis},
        {"env_sampling", env_sampling},
        {"env_window", env_window},
        {"mis_compensation", mis_compensation},
        {"env",
         {{"spec", env.spec.empty() ? spec.env : env.spec},
          {"content_hash", env.content_hash},
          // the file's name, not its path: provenance holds no machine paths (issue 15)
          {"source_file", std::filesystem::path(env.source_path).filename().string()},
          {"width", env.equirect.cols},
          {"height", env.equirect.rows},
          {"negatives_clamped", env.negatives_clamped},
          {"rotation_deg", env.rotation_deg}}},
        {"estimator", estimator_description(env_sampling == "window", env_window == "lobe", mis_compensation,
                                            adaptive ? silhouette_boost : 1)},
        {"texture_fetches_per_pixel", r.texture_fetches_per_pixel},
        {"time_s", total_s},
    };
    return out;
}

double relative_rmse(const cv::Mat& a, const cv::Mat& b, const cv::Mat& coverage, double* mean_value) {
    // Per-pixel relative error (relMSE, Rousselle et al. 2011): each squared difference is divided by
    // the squared local value, so a pixel that straddles the 1e5 sun's reflection weighs no more than
    // a dim one. The 1e-2 keeps black pixels from dividing by zero.
    double rel = 0, sum = 0;
    long n = 0;
    for (int y = 0; y < a.rows; ++y)
        for (int x = 0; x < a.cols; ++x) {
            if (coverage.at<float>(y, x) <= 0) continue;
            const auto& pa = a.at<cv::Vec3f>(y, x);
            const auto& pb = b.at<cv::Vec3f>(y, x);
            for (int c = 0; c < 3; ++c) {
                double d = double(pa[c]) - pb[c], m = 0.5 * (double(pa[c]) + pb[c]);
                rel += d * d / (m * m + 1e-2);
                sum += m;
            }
            ++n;
        }
    if (n == 0) return 0;
    if (mean_value) *mean_value = sum / (3.0 * n);
    return std::sqrt(rel / (3.0 * n));
}

NoiseFloor measure_noise_floor(const TestSpec& spec_in, int spp) {
    auto t0 = std::chrono::steady_clock::now();
    TestSpec spec = spec_in;
    NoiseFloor nf;
    nf.spp = spp;
    nf.seed_a = spec.options.get_int("seed", 0);
    nf.seed_b = nf.seed_a + 1;
    Environment env = load_environment(spec.env);
    spec.options.set("spp", std::to_string(spp));
    spec.options.set("seed", std::to_string(nf.seed_a));
    ReferenceRender a = render_reference_full(spec, &env);
    spec.options.set("seed", std::to_string(nf.seed_b));
    ReferenceRender b = render_reference_full(spec, &env);
    nf.relative_rmse = relative_rmse(a.result.image, b.result.image, a.coverage, &nf.mean_value);
    nf.covered_pixels = cv::countNonZero(a.coverage > 0);
    nf.image_a = a.result.image;
    nf.image_b = b.result.image;
    nf.provenance_a = a.result.provenance;
    nf.coverage = a.coverage;
    nf.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return nf;
}

} // namespace iblcheck
