// One lighting sample of the Monte Carlo integrator (mc_shade.h).
#include "renderers/reference/monte_carlo/mc_shade.h"

#include <algorithm>
#include <cmath>

#include "renderers/reference/monte_carlo/mc_sampling.h"

namespace iblcheck::reference {

BrdfEval::BrdfEval(const MatConst& m, Vec3d view_local, double p_specular) : M(m), vl(view_local), p_s(p_specular) {
    nv = vl.z;
    const double a2 = M.a2;
    const double lambda_v = std::sqrt(a2 + (1 - a2) * nv * nv);
    vndf_norm = 1.0 / (2 * (nv + lambda_v));
    gv_term = std::sqrt(nv * nv * (1.0 - a2) + a2); // for V (material_model.h)
}

double BrdfEval::operator()(Vec3d l, double fc[3]) const {
    const double a2 = M.a2;
    double nl = l.z;
    for (int i = 0; i < 3; ++i) fc[i] = M.kd[i] * nl;
    double p = (1 - p_s) * nl / model::kPi;
    if (M.cont_spec) {
        Vec3d h = normalize(l + vl);
        double nh = h.z, vh = dot(vl, h);
        double d = model::d_ggx(nh, M.alpha);
        // V = 0.5 / (n·l √(n·v²(1−α²)+α²) + n·v √(n·l²(1−α²)+α²)), exactly material_model.h's.
        double vis = 0.5 / (nl * gv_term + nv * std::sqrt(nl * nl * (1.0 - a2) + a2));
        double dv = d * vis * nl;
        for (int i = 0; i < 3; ++i) fc[i] += dv * model::f_schlick(M.f0[i], vh);
        // VNDF: D(h) G1(v) max(0, v·h) / (n·v) / (4 v·h) = D / (2 (n·v + Λ_v))
        p += p_s * d * vndf_norm;
    }
    return p;
}

double specular_probability(const MatConst& M, double nv) {
    if (!M.want_diff) return 1;
    if (!M.cont_spec) return 0;
    double sw = 0;
    for (int i = 0; i < 3; ++i) sw += model::f_schlick(M.f0[i], nv);
    return std::clamp(sw / (sw + M.dw), 0.1, 0.9);
}

namespace {
// The view direction in the local frame, n·v clamped to ≥ kMinNdotV (the last sliver of the silhouette).
Vec3d local_view(const ShadingFrame& f, Vec3d v) {
    Vec3d vl = f.to_local(v);
    if (vl.z < kMinNdotV) {
        double s = std::sqrt(std::max(0.0, 1 - kMinNdotV * kMinNdotV) / std::max(1e-300, vl.x * vl.x + vl.y * vl.y));
        vl = Vec3d{vl.x * s, vl.y * s, kMinNdotV};
        if (!std::isfinite(s)) vl = Vec3d{std::sqrt(1 - kMinNdotV * kMinNdotV), 0, kMinNdotV};
    }
    return vl;
}

// Delta lobe: ∫ D V F (n·l) L dl -> F(v·n) L(reflect(v)) (G2 = 1 at α = 0).
void add_mirror(const Shader& S, const MatConst& M, const ShadingFrame& f, Vec3d vl, double out[3], long& fetches) {
    Vec3d r = f.to_world(Vec3d{-vl.x, -vl.y, vl.z});
    double rd[3] = {r.x, r.y, r.z}, u, vv, L[3];
    S.dist.to_uv(rd, u, vv);
    S.img.lookup(u, vv, L);
    ++fetches;
    for (int i = 0; i < 3; ++i) out[i] += model::f_schlick(M.f0[i], vl.z) * L[i];
}

// (a) BRDF sampling: the lobe chosen by splitting u1 at p_s (select_lobe), weighted against the
// environment strategy's (windowed) pdf of the same direction.
void add_brdf_sample(const Shader& S, const EnvWindow& win, const ShadingFrame& f, const BrdfEval& eval, double u0, double u1,
                     double out[3], long& fetches) {
    const bool pick_spec = select_lobe(eval.p_s, u1);
    const Vec3d l =
        pick_spec ? reflect_about(eval.vl, sample_ggx_vndf(eval.vl, eval.M.alpha, u0, u1)) : sample_cosine_hemisphere(u0, u1);
    if (l.z <= 0) return;
    double fc[3];
    const double pb = eval(l, fc);
    if (pb <= 0) return;
    Vec3d lw = f.to_world(l);
    double lwd[3] = {lw.x, lw.y, lw.z}, u, vv, L[3];
    S.dist.to_uv(lwd, u, vv);
    double pe = win.pdf(S.dist, u, vv, S.dist.pdf_uv(u, vv));
    double w = mis_weight_brdf_sample(pb, pe, S.power);
    S.img.lookup(u, vv, L);
    ++fetches;
    for (int i = 0; i < 3; ++i) out[i] += fc[i] * L[i] * (w / pb);
}

// (b) Environment sampling from (e0, e1), weighted against the BRDF strategy's pdf.
void add_env_sample(const Shader& S, const EnvWindow& win, const ShadingFrame& f, const BrdfEval& eval, double e0, double e1,
                    double out[3], long& fetches) {
    double dw[3], u, vv;
    const double pe = sample_env_window(S.dist, win, e0, e1, dw, u, vv);
    if (!(pe > 0)) return;
    const Vec3d ll = f.to_local(Vec3d{dw[0], dw[1], dw[2]});
    if (ll.z <= 0) return;
    double fc[3], L[3];
    double pb = eval(ll, fc);
    double w = mis_weight_env_sample(pe, pb, S.power);
    S.img.lookup(u, vv, L);
    ++fetches;
    for (int i = 0; i < 3; ++i) out[i] += fc[i] * L[i] * (w / pe);
}
} // namespace

void shade(const Shader& S, const MatConst& M, const EnvWindow& win, Vec3d n, Vec3d v, const LightSeeds& seeds, uint32_t k,
           double out[3], long& fetches) {
    const ShadingFrame f(n); // Duff et al. 2017
    const Vec3d vl = local_view(f, v);
    if (M.want_spec && M.mirror) add_mirror(S, M, f, vl, out, fetches);
    if (!M.want_diff && !M.cont_spec) return;
    const BrdfEval eval(M, vl, specular_probability(M, vl.z));
    double u0, u1;
    sobol_owen_2d(k, seeds.brdf, u0, u1);
    add_brdf_sample(S, win, f, eval, u0, u1, out, fetches);
    if (S.dist.empty()) return;
    double e0, e1;
    sobol_owen_2d(k, seeds.env, e0, e1);
    add_env_sample(S, win, f, eval, e0, e1, out, fetches);
}

} // namespace iblcheck::reference
