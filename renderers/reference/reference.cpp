// CPU reference integrator; the estimator is described in reference.h.
#include "renderers/reference/reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "renderers/material_model.h"

namespace iblcheck {

namespace reference {

namespace {
constexpr double kPi = model::kPi;

uint32_t reverse_bits(uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
}

// Laine–Karras style permutation (Burley 2020, listing 3, improved constants).
uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
    x = reverse_bits(x);
    x = laine_karras_permutation(x, seed);
    return reverse_bits(x);
}

// Sobol dimension 1 (primitive polynomial x + 1); dimension 0 is reverse_bits(index).
uint32_t sobol_dim1(uint32_t index) {
    uint32_t v = 1u << 31, r = 0;
    for (; index; index >>= 1, v ^= v >> 1)
        if (index & 1) r ^= v;
    return r;
}

uint32_t hash_combine(uint32_t seed, uint32_t v) { return seed ^ (v + 0x9e3779b9u + (seed << 6) + (seed >> 2)); }
} // namespace

uint32_t hash_u32(uint32_t x) {
    // lowbias32 (Chris Wellons)
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

void sobol_owen_2d(uint32_t index, uint32_t seed, double& x, double& y) {
    uint32_t i = nested_uniform_scramble(index, seed);
    uint32_t sx = nested_uniform_scramble(reverse_bits(i), hash_combine(seed, 0));
    uint32_t sy = nested_uniform_scramble(sobol_dim1(i), hash_combine(seed, 1));
    // 24 random bits -> exactly representable, strictly < 1.
    x = double(sx >> 8) * (1.0 / 16777216.0);
    y = double(sy >> 8) * (1.0 / 16777216.0);
}

EnvDistribution::EnvDistribution(const Environment& env) {
    const cv::Mat& m = env.equirect;
    w_ = m.cols, h_ = m.rows;
    double a = double(env.rotation_deg) * kPi / 180;
    rot_c_ = std::cos(a), rot_s_ = std::sin(a);
    std::vector<double> lum(size_t(w_) * h_);
    for (int j = 0; j < h_; ++j)
        for (int i = 0; i < w_; ++i) {
            const auto& p = m.at<cv::Vec3f>(j, i);
            lum[size_t(j) * w_ + i] = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        }
    pdf_.assign(size_t(w_) * h_, 0.0f);
    row_dcos_.assign(h_, 0.0);
    row_cos_top_.assign(h_, 0.0);
    marginal_cdf_.assign(h_ + 1, 0.0);
    conditional_cdf_.assign(size_t(h_) * (w_ + 1), 0.0);
    std::vector<double> prob(size_t(w_) * h_, 0.0);
    for (int j = 0; j < h_; ++j) {
        // Exact solid angle of the row's pixels / (2π/W): cos θ_top − cos θ_bottom.
        row_cos_top_[j] = std::cos(j * kPi / h_);
        double st = row_cos_top_[j] - std::cos((j + 1) * kPi / h_);
        row_dcos_[j] = st;
        double* cdf = &conditional_cdf_[size_t(j) * (w_ + 1)];
        cdf[0] = 0;
        for (int i = 0; i < w_; ++i) {
            double mx = 0;
            for (int dj = -1; dj <= 1; ++dj) {
                int jj = std::clamp(j + dj, 0, h_ - 1);
                for (int di = -1; di <= 1; ++di) {
                    int ii = (i + di + w_) % w_;
                    mx = std::max(mx, lum[size_t(jj) * w_ + ii]);
                }
            }
            double wgt = mx * st;
            prob[size_t(j) * w_ + i] = wgt;
            cdf[i + 1] = cdf[i] + wgt;
        }
        marginal_cdf_[j + 1] = marginal_cdf_[j] + cdf[w_];
    }
    total_ = marginal_cdf_[h_];
    if (total_ <= 0) return;
    // Solid-angle pdf of each pixel, P_pixel / Ω_pixel, stored once (float: the same value is used by
    // sample() and pdf(), so the estimator stays exactly consistent; rounding is a 1e-7 relative effect).
    for (int j = 0; j < h_; ++j)
        for (int i = 0; i < w_; ++i)
            pdf_[size_t(j) * w_ + i] = float(prob[size_t(j) * w_ + i] / total_ * double(w_) / (2 * kPi * row_dcos_[j]));
    // Guide tables (Chen & Asau 1974 "cutpoint" method): guide[g] = first index whose cumulative mass
    // exceeds g/G of the total, so inverting the CDF is O(1) expected and still monotone in u (the
    // Sobol stratification carries over to the environment, which an alias table would lose).
    auto build_guide = [](const double* cdf, int n, std::vector<int>& guide, size_t off) {
        const double tot = cdf[n];
        int i = 0;
        for (int g = 0; g < n; ++g) {
            double t = tot * double(g) / n;
            while (i < n - 1 && cdf[i + 1] <= t) ++i;
            guide[off + g] = i;
        }
    };
    marginal_guide_.assign(h_, 0);
    build_guide(marginal_cdf_.data(), h_, marginal_guide_, 0);
    conditional_guide_.assign(size_t(h_) * w_, 0);
    for (int j = 0; j < h_; ++j)
        if (conditional_cdf_[size_t(j) * (w_ + 1) + w_] > 0)
            build_guide(&conditional_cdf_[size_t(j) * (w_ + 1)], w_, conditional_guide_, size_t(j) * w_);
}

// First index i in [0, n) with cdf[i + 1] > t (the upper_bound), from the guide; never an empty bin.
static inline int invert_cdf(const double* cdf, const int* guide, int n, double t) {
    int g = int(t / cdf[n] * n);
    g = std::clamp(g, 0, n - 1);
    int i = guide[g];
    while (i > 0 && cdf[i] > t) --i; // rounding in g: never past the answer
    while (i < n - 1 && cdf[i + 1] <= t) ++i;
    while (i > 0 && cdf[i + 1] - cdf[i] <= 0) --i; // t at the very top: step back onto mass
    return i;
}

double EnvDistribution::sample_uv(double u1, double u2, double dir[3], double& u, double& v) const {
    if (total_ <= 0) return 0;
    // Row from the marginal.
    double t = u2 * total_;
    int j = invert_cdf(marginal_cdf_.data(), marginal_guide_.data(), h_, t);
    double row_w = marginal_cdf_[j + 1] - marginal_cdf_[j];
    double dv = std::clamp((t - marginal_cdf_[j]) / row_w, 0.0, 1.0 - 1e-12);
    const double* cdf = &conditional_cdf_[size_t(j) * (w_ + 1)];
    double s = u1 * cdf[w_];
    int i = invert_cdf(cdf, &conditional_guide_[size_t(j) * w_], w_, s);
    double du = std::clamp((s - cdf[i]) / (cdf[i + 1] - cdf[i]), 0.0, 1.0 - 1e-12);
    u = (i + du) / w_;
    double phi = (u - 0.5) * 2 * kPi;
    // Uniform in solid angle inside the pixel: cos θ uniform between the row's edges.
    double ct = row_cos_top_[j] - dv * row_dcos_[j];
    ct = std::clamp(ct, -1.0, 1.0);
    // v from cos θ, kept inside row j (the pdf below is row j's).
    v = std::clamp(std::acos(ct) / kPi, double(j) / h_, std::nextafter(double(j + 1) / h_, 0.0));
    double st = std::sqrt(std::max(0.0, 1 - ct * ct));
    double e[3] = {st * std::sin(phi), ct, -st * std::cos(phi)};
    // env -> world: R_y(+rotation)
    dir[0] = rot_c_ * e[0] + rot_s_ * e[2];
    dir[1] = e[1];
    dir[2] = -rot_s_ * e[0] + rot_c_ * e[2];
    return pdf_[size_t(j) * w_ + i];
}

double EnvDistribution::sample(double u1, double u2, double dir[3]) const {
    double u, v;
    return sample_uv(u1, u2, dir, u, v);
}

void EnvDistribution::to_uv(const double d[3], double& u, double& v) const {
    // world -> env: R_y(-rotation)
    double x = rot_c_ * d[0] - rot_s_ * d[2], z = rot_s_ * d[0] + rot_c_ * d[2];
    double y = std::clamp(d[1], -1.0, 1.0);
    u = 0.5 + std::atan2(x, -z) / (2 * kPi), v = std::acos(y) / kPi;
}

double EnvDistribution::pdf_uv(double u, double v) const {
    if (total_ <= 0) return 0;
    int i = std::clamp(int(u * w_), 0, w_ - 1), j = std::clamp(int(v * h_), 0, h_ - 1);
    return pdf_[size_t(j) * w_ + i];
}

double EnvDistribution::pdf(const double d[3]) const {
    double u, v;
    to_uv(d, u, v);
    return pdf_uv(u, v);
}

} // namespace reference

namespace {
using reference::EnvDistribution;
constexpr double kPi = model::kPi;
constexpr double kMirrorAlpha = 1e-4;
constexpr double kMinNdotV = 1e-5;

struct V3 {
    double x, y, z;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline V3 normalize(V3 a) { return (1.0 / std::sqrt(dot(a, a))) * a; }

enum class Lobes { all, diffuse, specular };

// The equirect with environment.h's bilinear filter (sample_bilinear: texel centres at (i + 0.5)/W,
// u wraps, v clamps), addressed by uv so that the direction -> uv trigonometry is done once per
// direction and shared with the pdf lookup.
struct EnvImage {
    const float* data = nullptr;
    int W = 0, H = 0;
    size_t stride = 0; // floats per row
    explicit EnvImage(const cv::Mat& m)
        : data(m.ptr<float>(0)), W(m.cols), H(m.rows), stride(m.step1()) {}
    void lookup(double u, double v, double rgb[3]) const { bilinear_equirect(data, W, H, stride, u, v, rgb); }
};

struct Shader {
    const EnvImage& img;
    const EnvDistribution& dist;
    Lobes lobes;
    bool power = true; // MIS heuristic: power (β = 2) or balance
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

// Per-pixel scramble seeds of the lighting dimensions.
struct LightSeeds {
    uint32_t brdf, select, env;
};

// Shades one camera sub-sample: world normal n, direction to the viewer v; adds into out[3].
void shade(const Shader& S, const MatConst& M, V3 n, V3 v, const LightSeeds& seeds, uint32_t k, double out[3],
           long& fetches) {
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
    if (!want_diff) p_s = 1;
    else if (!cont_spec) p_s = 0;
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
        V3 vh = normalize({alpha * vl.x, alpha * vl.y, vl.z});
        double lensq = vh.x * vh.x + vh.y * vh.y;
        V3 T1 = lensq > 0 ? (1.0 / std::sqrt(lensq)) * V3{-vh.y, vh.x, 0} : V3{1, 0, 0};
        V3 T2 = cross(vh, T1);
        double r = std::sqrt(u0), phi = 2 * kPi * u1;
        double t1 = r * std::cos(phi), t2 = r * std::sin(phi);
        double s = 0.5 * (1 + vh.z);
        t2 = (1 - s) * std::sqrt(std::max(0.0, 1 - t1 * t1)) + s * t2;
        V3 nh = t1 * T1 + t2 * T2 + std::sqrt(std::max(0.0, 1 - t1 * t1 - t2 * t2)) * vh;
        V3 h = normalize({alpha * nh.x, alpha * nh.y, std::max(0.0, nh.z)});
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
            double pe = S.dist.pdf_uv(u, vv);
            double w = S.power ? pb / (pb + pe * (pe / pb)) : pb / (pb + pe);
            S.img.lookup(u, vv, L);
            ++fetches;
            for (int i = 0; i < 3; ++i) out[i] += fc[i] * L[i] * (w / pb);
        }
    }

    // (b) Environment sampling.
    if (!S.dist.empty()) {
        double e0, e1, dw[3], u, vv;
        reference::sobol_owen_2d(k, seeds.env, e0, e1);
        double pe = S.dist.sample_uv(e0, e1, dw, u, vv);
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

const char* kEstimator =
    "sub-pixel positions: an Owen-scrambled Sobol pattern per pixel keyed by pixel_pattern (not by the "
    "lighting seed); lighting per position: MIS (power heuristic, 1 sample each) of "
    "BRDF sampling [mixture of GGX VNDF (Heitz 2018) with p_s = F/(F+diffuse) clamped to [0.1,0.9], and "
    "cosine hemisphere] and environment sampling [piecewise-constant equirect distribution ~ 3x3-max "
    "luminance * solid angle, guide-table CDF inversion], whole BRDF per sample; alpha < 1e-4 treated as a "
    "mirror delta F(n.v) L(reflect); bilinear env lookups; no inter-sphere occlusion";

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
            if (D <= r) cand = true;
            else {
                double ang = std::acos(std::clamp(along / D, -1.0, 1.0));
                cand = ang <= std::asin(std::min(1.0, r / D)) + slack;
            }
        }
        if (cand) out.push_back(int(i));
    }
}

// Nearest hit among the candidate spheres: the arithmetic of scene.cpp's intersect().
bool intersect_candidates(const Scene& scene, const std::vector<int>& cand, Vec3f origin, Vec3f dir, int& sphere,
                          V3& normal) {
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
    const int positions = std::clamp(o.get_int("positions", std::max(1, spp / 4)), 1, std::max(1, spp));
    int threads = o.get_int("threads", 0);
    double rot = o.get_double("env_rotation", 0.0);
    std::string lobes_s = o.get_choice("lobes", "all", {"all", "diffuse", "specular"});
    std::string mis = o.get_choice("mis", "power", {"power", "balance"});
    if (spp < 1) throw UsageError("option 'spp': must be >= 1");
    if (threads < 0) throw UsageError("option 'threads': must be >= 0");
    Lobes lobes = lobes_s == "diffuse" ? Lobes::diffuse : lobes_s == "specular" ? Lobes::specular : Lobes::all;

    Environment env = env_in ? *env_in : load_environment(spec.env);
    if (o.has("env_rotation")) env.rotation_deg = float(rot);
    EnvDistribution dist(env);
    cv::Mat equirect = env.equirect.isContinuous() ? env.equirect : env.equirect.clone();
    EnvImage img(equirect);

    const int W = spec.width > 0 ? spec.width : scene.width;
    const int H = spec.height > 0 ? spec.height : scene.height;
    if (threads == 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    threads = std::min(threads, H);

    cv::Mat image(H, W, CV_32FC3, cv::Scalar(0, 0, 0));
    cv::Mat coverage(H, W, CV_32FC1, cv::Scalar(0));
    std::vector<long> row_fetches(H, 0);
    Shader S{img, dist, lobes, mis == "power"};
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
                V3 v = normalize({-d3.x, -d3.y, -d3.z});
                double pos[3] = {0, 0, 0};
                for (int m = 0; m < M; ++m) {
                    double one[3] = {0, 0, 0};
                    shade(S, mats[sph], nrm, v, seeds, uint32_t(k) * uint32_t(M) + uint32_t(m), one, fetches);
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
    // relative variance for the same work — partially covered silhouette pixels, whose few hits carry
    // all the lighting noise of a dim pixel, get many more. Clamped to [M̄/4, 16 M̄], M̄ = spp/P.
    // The pilot's samples are then discarded: the counts depend on the pilot only, the main samples
    // are independent of it, so each pixel's estimate stays unbiased.
    const int m_mean = std::max(1, int(std::lround(double(spp) / positions)));
    std::vector<int> counts(size_t(W) * H, m_mean);
    long pilot_samples = 0;
    if (adaptive) {
        std::vector<double> r(size_t(W) * H, -1.0);
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
        {"env", {{"spec", env.spec.empty() ? spec.env : env.spec},
                 {"content_hash", env.content_hash},
                 {"source_path", env.source_path},
                 {"width", env.equirect.cols},
                 {"height", env.equirect.rows},
                 {"negatives_clamped", env.negatives_clamped},
                 {"rotation_deg", env.rotation_deg}}},
        {"estimator", kEstimator},
        {"texture_fetches_per_pixel", r.texture_fetches_per_pixel},
        {"time_s", total_s},
    };
    return out;
}

RenderResult render_reference(const TestSpec& spec) { return render_reference_full(spec).result; }
RenderResult render_reference(const TestSpec& spec, const Environment& env) {
    return render_reference_full(spec, &env).result;
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
