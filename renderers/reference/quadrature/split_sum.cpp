// The split-sum rungs of the quadrature truth (split_sum.h).
#include "renderers/reference/quadrature/split_sum.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

namespace iblcheck::truth {

namespace {

// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n from Chebyshev guesses).
struct GaussLegendre {
    std::vector<double> x, w;
    explicit GaussLegendre(int n) : x(size_t(n)), w(size_t(n)) {
        for (int i = 0; i < n; ++i) {
            double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1;
            for (int it = 0; it < 100; ++it) {
                double p0 = 1, p1 = z;
                for (int k = 2; k <= n; ++k) {
                    const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                    p0 = p1, p1 = p2;
                }
                dp = n * (z * p1 - p0) / (z * z - 1);
                const double dz = p1 / dp;
                z -= dz;
                if (std::fabs(dz) < 1e-15) break;
            }
            x[size_t(i)] = z, w[size_t(i)] = 2 / ((1 - z * z) * dp * dp);
        }
    }
};

// Composite rule: `panels` equal panels of a 16-point rule over [a, b], calling f(x, weight).
template <class F> void integrate(double a, double b, int panels, F&& f) {
    static const GaussLegendre g(16);
    const double h = (b - a) / panels;
    for (int p = 0; p < panels; ++p)
        for (size_t k = 0; k < g.x.size(); ++k) f(a + h * (p + 0.5 * (g.x[k] + 1)), 0.5 * h * g.w[k]);
}

// The same with panels graded geometrically toward b (each half the one before, the last two equal):
// near the horizon cut V·(n·l) varies on the scale of α·n·v, which a uniform rule resolves slowly
// (n·v = 0.05, α = 0.04: 128 uniform panels were 1e-3 short; 16 graded ones converge to 1e-6).
template <class F> void integrate_graded(double a, double b, int panels, F&& f) {
    static const GaussLegendre g(16);
    double lo = a;
    for (int p = 0; p < panels; ++p) {
        const double hi = p == panels - 1 ? b : b - (b - a) * std::ldexp(1.0, -(p + 1));
        for (size_t k = 0; k < g.x.size(); ++k) f(lo + (hi - lo) * 0.5 * (g.x[k] + 1), 0.5 * (hi - lo) * g.w[k]);
        lo = hi;
    }
}

// h ~ D(h)(n·h): ξ ∈ [0, 1) ↦ cos²θ_h (the inverse of GGX's visible-free CDF).
double cos2_theta_h(double xi, double a2) { return (1 - xi) / (1 + (a2 - 1) * xi); }

} // namespace

// norm(α) = ∫ D(h)(n·l)⁺ dl at n = v. With l = reflect(v, h), dl = 4(v·h) dω_h = 4(n·h) dω_h and
// n·l = 2(n·h)² − 1, so norm = 4 ∫ (2(n·h)² − 1)⁺ D(h)(n·h) dω_h = 4 E_{h ~ D(n·h)}[(2cos²θ_h − 1)⁺].
// Under the measure dP = D(h)(n·h) dω_h, ξ = P(θ < θ_h) is uniform and cos²θ_h = (1 − ξ)/(1 + kξ),
// k = α² − 1; n·l > 0 ⇔ cos²θ_h > 1/2 ⇔ ξ < ξ* = 1/(1 + α²). So
//   norm = 4 ∫₀^ξ* (2(1 − ξ)/(1 + kξ) − 1) dξ = 4 (2 I − ξ*),  I = ∫₀^ξ* (1 − ξ)/(1 + kξ) dξ
//        = −ξ*/k + (1 + k) ln(1 + kξ*)/k²     (k ≠ 0),
// and by its series Σ_m (−k)^m (ξ*^{m+1}/(m+1) − ξ*^{m+2}/(m+2)) when |k|ξ* is small (α near 1,
// where the closed form cancels). α → 0: (1 + k) ln(…) = α² ln(α²/(1 + α²)) → 0, I → ξ* → 1: norm → 4.
// α = 1: I = 3/8, norm = 1.
double prefilter_norm(double alpha) {
    const double a2 = alpha * alpha, k = a2 - 1, xs = 1 / (1 + a2);
    double I = 0;
    if (std::fabs(k) * xs < 0.25) {
        double km = 1, xm = xs; // (−k)^m, ξ*^{m+1}
        for (int m = 0; m < 60; ++m, km *= -k, xm *= xs) I += km * (xm / (m + 1) - xm * xs / (m + 2));
    } else {
        I = -xs / k + (1 + k) * std::log1p(k * xs) / (k * k);
    }
    return 4 * (2 * I - xs);
}

// A = ∫ D·V·(1 − Fc)·(n·l) dl, B = ∫ D·V·Fc·(n·l) dl, Fc = (1 − v·h)⁵. Over h ~ D(h)(n·h) (measure dP
// = dξ dφ/2π), dl = 4(v·h)dω_h, so the integrand is V·(n·l)·4(v·h)/(n·h): D cancels. n = z, v in the xz
// plane; φ ∈ [0, π] by symmetry. For fixed φ, n·l = cosθ_v cos2θ + sinθ_v cosφ sin2θ = ρ cos(2θ − δ),
// δ = atan2(sinθ_v cosφ, cosθ_v): l is above the horizon exactly for θ < θ_c = (δ + π/2)/2, so each φ
// integrates ξ ∈ [0, ξ(θ_c)] (no kink inside the rule). ξ = u² makes sinθ_h analytic in u (≈ u near 0),
// which a Gauss rule needs. 8 x 16 nodes in φ, 16 graded panels x 16 in u: 32k evaluations.
Dfg dfg_exact(double nv, double alpha) {
    nv = std::clamp(nv, kMinNdotV, 1.0);
    const double fc_nv = std::pow(1 - nv, 5);
    if (alpha < kMirrorAlpha) return {1 - fc_nv, fc_nv}; // the delta lobe: F(n·v), G2 = 1
    const double a2 = alpha * alpha, sv = std::sqrt(1 - nv * nv);
    const double gv = std::sqrt(nv * nv * (1 - a2) + a2);
    Dfg out;
    integrate(0, kPi, 8, [&](double phi, double wphi) {
        const double cphi = std::cos(phi);
        const double theta_c = 0.5 * (std::atan2(sv * cphi, nv) + kPi / 2), c2c = std::cos(theta_c) * std::cos(theta_c);
        const double xi_c = (1 - c2c) / (1 + c2c * (a2 - 1));
        integrate_graded(0, std::sqrt(xi_c), 16, [&](double u, double wu) {
            const double c2 = cos2_theta_h(u * u, a2), ct = std::sqrt(c2), st = std::sqrt(std::max(0.0, 1 - c2));
            const double vh = sv * st * cphi + nv * ct, nl = 2 * vh * ct - nv;
            if (nl <= 0 || vh <= 0) return;
            const double vis = 0.5 / (nl * gv + nv * std::sqrt(nl * nl * (1 - a2) + a2));
            const double g = vis * nl * 4 * vh / ct, fc = std::pow(1 - vh, 5);
            const double w = wphi / kPi * wu * 2 * u; // dφ/π, dξ = 2u du
            out.a += w * g * (1 - fc), out.b += w * g * fc;
        });
    });
    return out;
}

namespace {
// (A, B) per α on a grid over s ∈ [0, 1], θ_v = acos(n·v) = θ₁·sin(πs/2), θ₁ = acos(kMinNdotV), with
// Catmull–Rom between nodes. A and B are even, analytic functions of θ_v (n·v = 1 is a square-root
// point of n·v itself), and θ_v(s) is odd and analytic, so they are even and analytic in s; the grid
// is dense toward grazing (its last step in n·v is 3e-5), where a narrow lobe's DFG turns fast.
struct DfgCurve {
    static constexpr int kNodes = 257;
    double t1 = 0;
    std::vector<Dfg> v;
    explicit DfgCurve(double alpha) : t1(std::acos(kMinNdotV)), v(size_t(kNodes)) {
        for (int i = 0; i < kNodes; ++i) v[size_t(i)] = dfg_exact(std::cos(t1 * std::sin(kPi / 2 * i / (kNodes - 1))), alpha);
    }
    Dfg at(double nv) const {
        const double t = std::min(1.0, std::acos(std::clamp(nv, kMinNdotV, 1.0)) / t1);
        const double x = std::asin(t) * 2 / kPi * (kNodes - 1);
        const int i = std::clamp(int(x), 0, kNodes - 2);
        const double f = x - i;
        auto node = [&](int k) { return v[size_t(k < 0 ? -k : std::min(k, kNodes - 1))]; }; // even about s = 0
        const Dfg p0 = node(i - 1), p1 = node(i), p2 = node(i + 1), p3 = node(i + 2);
        auto cr = [f](double a, double b, double c, double d) {
            return b + 0.5 * f * (c - a + f * (2 * a - 5 * b + 4 * c - d + f * (3 * (b - c) + d - a)));
        };
        return {cr(p0.a, p1.a, p2.a, p3.a), cr(p0.b, p1.b, p2.b, p3.b)};
    }
};
} // namespace

Dfg dfg_exact_cached(double nv, double alpha) {
    static std::mutex m;
    static std::map<double, std::shared_ptr<const DfgCurve>> curves;
    std::shared_ptr<const DfgCurve> c;
    {
        std::lock_guard<std::mutex> lock(m);
        auto& slot = curves[alpha];
        if (!slot) slot = std::make_shared<const DfgCurve>(alpha); // 8.4M evaluations, once per roughness
        c = slot;
    }
    return c->at(nv);
}

Dfg env_brdf_approx(double roughness, double nv) {
    const double c0[4] = {-1.0, -0.0275, -0.572, 0.022}, c1[4] = {1.0, 0.0425, 1.04, -0.04};
    double r[4];
    for (int i = 0; i < 4; ++i) r[i] = roughness * c0[i] + c1[i];
    const double a004 = std::min(r[0] * r[0], std::exp2(-9.28 * nv)) * r[0] + r[1];
    return {-1.04 * a004 + r[2], 1.04 * a004 + r[3]};
}

void shade_split_sum(const EnvPyramid& env, const MaterialLobe& lobe, const ShadingPoint& s, const QuadratureParams& p,
                     double rgb[3], ShadeStats* stats) {
    MaterialLobe diffuse = lobe;
    diffuse.split_sum = SplitSum::off, diffuse.specular = false;
    if (diffuse.diffuse) shade(env, diffuse, s, p, rgb, stats);
    if (!lobe.glossy()) return;
    MaterialLobe pre = lobe;
    pre.split_sum = SplitSum::off, pre.diffuse = false, pre.prefilter = true;
    pre.inv_norm = 1 / prefilter_norm(lobe.alpha);
    for (double& k : pre.kd) k = 0;
    const V3 r = 2 * s.nv * s.n - s.v;
    double P[3] = {0, 0, 0};
    shade(env, pre, shading_point(r, r, pre), p, P, stats);
    const Dfg g =
        lobe.split_sum == SplitSum::exact ? dfg_exact_cached(s.nv, lobe.alpha) : env_brdf_approx(std::sqrt(lobe.alpha), s.nv);
    for (int q = 0; q < 3; ++q) rgb[q] += P[q] * (lobe.f0[q] * g.a + g.b);
}

} // namespace iblcheck::truth
