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
    prob_.assign(size_t(w_) * h_, 0.0);
    row_dcos_.assign(h_, 0.0);
    marginal_cdf_.assign(h_ + 1, 0.0);
    conditional_cdf_.assign(size_t(h_) * (w_ + 1), 0.0);
    for (int j = 0; j < h_; ++j) {
        // Exact solid angle of the row's pixels / (2π/W): cos θ_top − cos θ_bottom.
        double st = std::cos(j * kPi / h_) - std::cos((j + 1) * kPi / h_);
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
            prob_[size_t(j) * w_ + i] = wgt;
            cdf[i + 1] = cdf[i] + wgt;
        }
        marginal_cdf_[j + 1] = marginal_cdf_[j] + cdf[w_];
    }
    total_ = marginal_cdf_[h_];
    if (total_ > 0)
        for (auto& p : prob_) p /= total_;
}

double EnvDistribution::sample(double u1, double u2, double dir[3]) const {
    if (total_ <= 0) return 0;
    // Row from the marginal.
    double t = u2 * total_;
    int j = int(std::upper_bound(marginal_cdf_.begin() + 1, marginal_cdf_.end(), t) - (marginal_cdf_.begin() + 1));
    j = std::clamp(j, 0, h_ - 1);
    while (j > 0 && marginal_cdf_[j + 1] - marginal_cdf_[j] <= 0) --j; // never land on an empty row
    while (j < h_ - 1 && marginal_cdf_[j + 1] - marginal_cdf_[j] <= 0) ++j;
    double row_w = marginal_cdf_[j + 1] - marginal_cdf_[j];
    double dv = std::clamp((t - marginal_cdf_[j]) / row_w, 0.0, 1.0 - 1e-12);
    const double* cdf = &conditional_cdf_[size_t(j) * (w_ + 1)];
    double s = u1 * cdf[w_];
    int i = int(std::upper_bound(cdf + 1, cdf + w_ + 1, s) - (cdf + 1));
    i = std::clamp(i, 0, w_ - 1);
    while (i > 0 && cdf[i + 1] - cdf[i] <= 0) --i;
    while (i < w_ - 1 && cdf[i + 1] - cdf[i] <= 0) ++i;
    double du = std::clamp((s - cdf[i]) / (cdf[i + 1] - cdf[i]), 0.0, 1.0 - 1e-12);
    double u = (i + du) / w_;
    double phi = (u - 0.5) * 2 * kPi;
    // Uniform in solid angle inside the pixel: cos θ uniform between the row's edges.
    double ct = std::cos(j * kPi / h_) - dv * row_dcos_[j];
    ct = std::clamp(ct, -1.0, 1.0);
    double st = std::sqrt(std::max(0.0, 1 - ct * ct));
    double e[3] = {st * std::sin(phi), ct, -st * std::cos(phi)};
    // env -> world: R_y(+rotation)
    dir[0] = rot_c_ * e[0] + rot_s_ * e[2];
    dir[1] = e[1];
    dir[2] = -rot_s_ * e[0] + rot_c_ * e[2];
    return prob_[size_t(j) * w_ + i] * double(w_) / (2 * kPi * row_dcos_[j]);
}

double EnvDistribution::pdf(const double d[3]) const {
    if (total_ <= 0) return 0;
    // world -> env: R_y(-rotation)
    double x = rot_c_ * d[0] - rot_s_ * d[2], z = rot_s_ * d[0] + rot_c_ * d[2];
    double y = std::clamp(d[1], -1.0, 1.0);
    double u = 0.5 + std::atan2(x, -z) / (2 * kPi), v = std::acos(y) / kPi;
    int i = std::clamp(int(u * w_), 0, w_ - 1), j = std::clamp(int(v * h_), 0, h_ - 1);
    return prob_[size_t(j) * w_ + i] * double(w_) / (2 * kPi * row_dcos_[j]);
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
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
V3 normalize(V3 a) { return (1.0 / std::sqrt(dot(a, a))) * a; }

enum class Lobes { all, diffuse, specular };

struct Shader {
    const Environment& env;
    const EnvDistribution& dist;
    Lobes lobes;
    bool power = true; // MIS heuristic: power (β = 2) or balance
};

void lookup(const Environment& env, V3 d, double rgb[3], long& fetches) {
    float df[3] = {float(d.x), float(d.y), float(d.z)}, c[3];
    sample_bilinear(env, df, c);
    rgb[0] = c[0], rgb[1] = c[1], rgb[2] = c[2];
    ++fetches;
}

// Shades one camera sub-sample: world normal n, direction to the viewer v; adds into out[3].
void shade(const Shader& S, const Material& mat, V3 n, V3 v, uint32_t pix_seed, uint32_t k, double out[3],
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
    const double alpha = model::alpha_from_roughness(mat.roughness);
    const double m = mat.metallic;
    const double c[3] = {mat.base_color.x, mat.base_color.y, mat.base_color.z};
    double f0[3];
    for (int i = 0; i < 3; ++i) f0[i] = model::f0_from(c[i], m);
    const bool want_diff = S.lobes != Lobes::specular && m < 1;
    const bool want_spec = S.lobes != Lobes::diffuse;
    const bool mirror = alpha < kMirrorAlpha;
    double kd[3];
    for (int i = 0; i < 3; ++i) kd[i] = want_diff ? (1 - m) * c[i] / kPi : 0.0;

    if (want_spec && mirror) {
        // Delta lobe: ∫ D V F (n·l) L dl -> F(v·n) L(reflect(v)) (G2 = 1 at α = 0).
        V3 r{-vl.x, -vl.y, vl.z};
        double L[3];
        lookup(S.env, to_world(r), L, fetches);
        for (int i = 0; i < 3; ++i) out[i] += model::f_schlick(f0[i], nv) * L[i];
    }
    const bool cont_spec = want_spec && !mirror;
    if (!want_diff && !cont_spec) return;

    double p_s;
    if (!want_diff) p_s = 1;
    else if (!cont_spec) p_s = 0;
    else {
        double sw = 0, dw = 0;
        for (int i = 0; i < 3; ++i) sw += model::f_schlick(f0[i], nv), dw += (1 - m) * c[i];
        p_s = std::clamp(sw / (sw + dw), 0.1, 0.9);
    }
    const double a2 = alpha * alpha;
    const double lambda_v = std::sqrt(a2 + (1 - a2) * nv * nv);

    // f(l)·(n·l) per channel for local l (n·l > 0), and the BRDF-strategy pdf.
    auto eval = [&](V3 l, double fc[3]) {
        double nl = l.z;
        for (int i = 0; i < 3; ++i) fc[i] = kd[i] * nl;
        if (cont_spec) {
            V3 h = normalize(l + vl);
            double nh = h.z, vh = dot(vl, h);
            double dv = model::d_ggx(nh, alpha) * model::v_smith_ggx_correlated(nv, nl, alpha) * nl;
            for (int i = 0; i < 3; ++i) fc[i] += dv * model::f_schlick(f0[i], vh);
        }
    };
    auto pdf_brdf = [&](V3 l) {
        double p = (1 - p_s) * l.z / kPi;
        if (cont_spec && p_s > 0) {
            V3 h = normalize(l + vl);
            // VNDF: D(h) G1(v) max(0, v·h) / (n·v) / (4 v·h) = D / (2 (n·v + Λ_v))
            p += p_s * model::d_ggx(h.z, alpha) / (2 * (nv + lambda_v));
        }
        return p;
    };

    double u0, u1, sel, unused;
    reference::sobol_owen_2d(k, reference::hash_u32(pix_seed ^ 0x68bc21ebu), u0, u1);
    reference::sobol_owen_2d(k, reference::hash_u32(pix_seed ^ 0x02e5be93u), sel, unused);

    // (a) BRDF sampling.
    V3 l;
    if (sel < p_s) {
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
        double pb = pdf_brdf(l);
        if (pb > 0) {
            V3 lw = to_world(l);
            double lwd[3] = {lw.x, lw.y, lw.z};
            double pe = S.dist.pdf(lwd);
            double w = S.power ? pb * pb / (pb * pb + pe * pe) : pb / (pb + pe);
            double fc[3], L[3];
            eval(l, fc);
            lookup(S.env, lw, L, fetches);
            for (int i = 0; i < 3; ++i) out[i] += fc[i] * L[i] * w / pb;
        }
    }

    // (b) Environment sampling.
    if (!S.dist.empty()) {
        double e0, e1, dw[3];
        reference::sobol_owen_2d(k, reference::hash_u32(pix_seed ^ 0x7b3f9a11u), e0, e1);
        double pe = S.dist.sample(e0, e1, dw);
        if (pe > 0) {
            V3 lw{dw[0], dw[1], dw[2]};
            V3 ll{dot(lw, t), dot(lw, bt), dot(lw, n)};
            if (ll.z > 0) {
                double pb = pdf_brdf(ll);
                double w = S.power ? pe * pe / (pe * pe + pb * pb) : pe / (pe + pb);
                double fc[3], L[3];
                eval(ll, fc);
                lookup(S.env, lw, L, fetches);
                for (int i = 0; i < 3; ++i) out[i] += fc[i] * L[i] * w / pe;
            }
        }
    }
}

const char* kEstimator =
    "per-pixel Owen-scrambled Sobol sub-pixel stratification; MIS (power heuristic, 1 sample each) of "
    "BRDF sampling [mixture of GGX VNDF (Heitz 2018) with p_s = F/(F+diffuse) clamped to [0.1,0.9], and "
    "cosine hemisphere] and environment sampling [piecewise-constant equirect distribution ~ 3x3-max "
    "luminance * sin(theta)], whole BRDF per sample; alpha < 1e-4 treated as a mirror delta "
    "F(n.v) L(reflect); bilinear env lookups; no inter-sphere occlusion";

} // namespace

ReferenceRender render_reference_full(const TestSpec& spec, const Environment* env_in) {
    auto t0 = std::chrono::steady_clock::now();
    Scene scene = build_scene(spec.scene, spec.options);
    const OptionMap& o = spec.options;
    int spp = o.get_int("spp", kReferenceDefaultSpp);
    int seed = o.get_int("seed", 0);
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

    const int W = spec.width > 0 ? spec.width : scene.width;
    const int H = spec.height > 0 ? spec.height : scene.height;
    if (threads == 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
    threads = std::min(threads, H);

    cv::Mat image(H, W, CV_32FC3, cv::Scalar(0, 0, 0));
    cv::Mat coverage(H, W, CV_32FC1, cv::Scalar(0));
    std::vector<long> row_fetches(H, 0);
    Shader S{env, dist, lobes, mis == "power"};
    const uint32_t seed_hash = reference::hash_u32(uint32_t(seed) * 0x9e3779b9u + 0x85ebca6bu);

    std::atomic<int> next_row{0};
    auto worker = [&] {
        for (int y; (y = next_row.fetch_add(1)) < H;) {
            long fetches = 0;
            for (int x = 0; x < W; ++x) {
                uint32_t pix_seed = reference::hash_u32(seed_hash ^ reference::hash_u32(uint32_t(y) * uint32_t(W) + uint32_t(x)));
                double acc[3] = {0, 0, 0};
                int hits = 0;
                for (int k = 0; k < spp; ++k) {
                    double sx, sy;
                    reference::sobol_owen_2d(uint32_t(k), pix_seed, sx, sy);
                    Vec3f o3, d3;
                    camera_ray(scene, W, H, x + sx, y + sy, o3, d3);
                    Hit hit = intersect(scene, o3, d3);
                    if (!hit.hit) continue;
                    ++hits;
                    const Sphere& sp = scene.spheres[hit.sphere];
                    V3 n = normalize({hit.normal.x, hit.normal.y, hit.normal.z});
                    V3 v = normalize({-d3.x, -d3.y, -d3.z});
                    shade(S, sp.material, n, v, pix_seed, uint32_t(k), acc, fetches);
                }
                auto& px = image.at<cv::Vec3f>(y, x);
                for (int i = 0; i < 3; ++i) px[i] = float(acc[i] / spp);
                coverage.at<float>(y, x) = float(hits) / float(spp);
            }
            row_fetches[y] = fetches;
        }
    };
    auto t1 = std::chrono::steady_clock::now();
    std::vector<std::thread> pool;
    for (int i = 1; i < threads; ++i) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();
    auto t2 = std::chrono::steady_clock::now();

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
