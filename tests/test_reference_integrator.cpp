// The Monte Carlo reference integrator (renderers/reference/monte_carlo/monte_carlo.h) end to end: checked against
// values computed here by an independent deterministic quadrature of material_model.h, and against closed
// forms; determinism, provenance, noise floor, the sub-pixel pattern. Its environment sampling is tested in
// test_reference_env_sampling.cpp, its pieces beside them (renderers/reference/mc_*_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "renderers/material_model.h"
#include "renderers/reference/reference.h"
#include "tests/reference_spec.h"

using namespace iblcheck;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_reference_integrator {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Gauss–Legendre nodes/weights on [0, 1].
void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
    x.resize(n), w.resize(n);
    for (int i = 0; i < n; ++i) {
        double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), pp = 0;
        for (int it = 0; it < 100; ++it) {
            double p1 = 1, p2 = 0;
            for (int j = 1; j <= n; ++j) {
                double p3 = p2;
                p2 = p1;
                p1 = ((2 * j - 1) * z * p2 - (j - 1) * p3) / j;
            }
            pp = n * (z * p1 - p2) / (z * z - 1);
            double dz = p1 / pp;
            z -= dz;
            if (std::fabs(dz) < 1e-15) break;
        }
        x[i] = 0.5 * (1 - z);
        w[i] = 1.0 / ((1 - z * z) * pp * pp);
    }
}

// Specular directional albedo E(μ, α, F0) = ∫ D V F (n·l) dl of material_model.h, by quadrature over
// the half-vector: ξ ∈ [0,1] with cos²θ_h = (1−ξ)/(1+ξ(α²−1)) makes D·cos θ_h dω_h = dξ dφ/2π. For
// each θ_h the φ-range where n·l > 0 is |φ| < acos(c), c = −cot(2θ_h)·μ/sin θ_v (closed form): all φ
// for θ_h < π/4 − θ_v/2, none for θ_h > π/4 + θ_v/2. The ξ-integral is split at those two points and
// each piece uses Gauss–Legendre, so the integrands are smooth on every piece.
double spec_albedo(double mu, double alpha, double f0, int n = 96) {
    static std::vector<double> gx, gw;
    static int gn = 0;
    if (gn != n) gauss_legendre(n, gx, gw), gn = n;
    double sv = std::sqrt(std::max(0.0, 1 - mu * mu)), tv = std::acos(std::clamp(mu, -1.0, 1.0));
    double a2 = alpha * alpha;
    auto xi_of = [&](double th) {
        double c2 = std::cos(th) * std::cos(th);
        return (1 - c2) / (1 + c2 * (a2 - 1));
    };
    double xi1 = xi_of(kPi / 4 - tv / 2), xi2 = xi_of(kPi / 4 + tv / 2);
    auto inner = [&](double xi) {
        double c2 = (1 - xi) / (1 + xi * (a2 - 1));
        double ch = std::sqrt(c2), sh = std::sqrt(std::max(0.0, 1 - c2));
        double phimax;
        if (sv * sh < 1e-14)
            phimax = (2 * ch * ch - 1 > 0) ? kPi : 0;
        else {
            double c = (mu / (2 * ch) - mu * ch) / (sv * sh);
            phimax = c <= -1 ? kPi : c >= 1 ? 0 : std::acos(c);
        }
        if (phimax <= 0) return 0.0;
        double acc = 0;
        for (int b = 0; b < n; ++b) {
            double phi = gx[b] * phimax;
            double vh = sv * sh * std::cos(phi) + mu * ch;
            double nl = 2 * vh * ch - mu;
            if (nl <= 0 || vh <= 0) continue;
            acc += gw[b] * 4 * model::v_smith_ggx_correlated(mu, nl, alpha) * model::f_schlick(f0, vh) * nl * vh / ch;
        }
        return acc * (2 * phimax) / (2 * kPi); // φ ∈ (−φmax, φmax), symmetric
    };
    double sum = 0;
    if (xi1 > 0)
        for (int a = 0; a < n; ++a) sum += gw[a] * xi1 * inner(gx[a] * xi1);
    // Second piece: φmax(ξ) has square-root ends (acos near ±1); ξ = lo + (hi−lo)(1 − cos πt)/2 removes them.
    if (xi2 > xi1)
        for (int a = 0; a < n; ++a) {
            double t = gx[a];
            double xi = xi1 + (xi2 - xi1) * 0.5 * (1 - std::cos(kPi * t));
            sum += gw[a] * (xi2 - xi1) * 0.5 * kPi * std::sin(kPi * t) * inner(xi);
        }
    return sum;
}

// E(μ) tabulated on a fine μ grid (linear interpolation), for many pixels.
struct AlbedoTable {
    double alpha, f0;
    std::vector<double> e;
    static constexpr int kN = 1024;
    AlbedoTable(double a, double f) : alpha(a), f0(f), e(kN + 1) {
        for (int i = 0; i <= kN; ++i) e[i] = spec_albedo(std::max(1e-4, double(i) / kN), a, f);
    }
    double operator()(double mu) const {
        double x = std::clamp(mu, 0.0, 1.0) * kN;
        int i = std::min(int(x), kN - 1);
        return e[i] + (x - i) * (e[i + 1] - e[i]);
    }
};

using testutil::reference_spec;

// n·v averaged over a k×k grid inside pixel (x, y); false if any of the grid points (or the pixel's
// corners) misses its sphere, i.e. the pixel is not fully covered.
bool pixel_mu_grid(const Scene& s, int W, int H, int x, int y, int k, std::vector<double>& mus, int& sphere) {
    mus.clear();
    sphere = -1;
    for (int c = 0; c < 4; ++c) {
        Vec3f o, d;
        camera_ray(s, W, H, x + (c & 1), y + (c >> 1), o, d);
        Hit h = intersect(s, o, d);
        if (!h.hit) return false;
        if (sphere >= 0 && h.sphere != sphere) return false;
        sphere = h.sphere;
    }
    for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
            Vec3f o, d;
            camera_ray(s, W, H, x + (i + 0.5) / k, y + (j + 0.5) / k, o, d);
            Hit h = intersect(s, o, d);
            if (!h.hit) return false;
            mus.push_back(-(h.normal.x * d.x + h.normal.y * d.y + h.normal.z * d.z));
        }
    return true;
}
} // namespace

TEST(Quadrature, KnownAlbedos) {
    // GGX + height-correlated Smith, F0 = 1, normal incidence (material_model.h).
    EXPECT_NEAR(spec_albedo(1.0, 0.25, 1.0), 0.91581, 5e-5);
    EXPECT_NEAR(spec_albedo(1.0, 1.0, 1.0), 1 - std::log(2.0), 5e-5);
    // Converged in the node count at an oblique angle too.
    EXPECT_NEAR(spec_albedo(0.3, 0.5625, 1.0, 96), spec_albedo(0.3, 0.5625, 1.0, 192), 1e-5);
    EXPECT_NEAR(spec_albedo(0.2, 0.0625, 1.0, 96), spec_albedo(0.2, 0.0625, 1.0, 192), 1e-5);
    EXPECT_NEAR(spec_albedo(0.05, 1.0, 0.04, 96), spec_albedo(0.05, 1.0, 0.04, 192), 1e-5);
    std::printf("E(mu=1): r=0.5 %.6f, r=1 %.6f (1-ln2 = %.6f)\n", spec_albedo(1.0, 0.25, 1.0), spec_albedo(1.0, 1.0, 1.0),
                1 - std::log(2.0));
}

// White furnace, metal F0 = 1: every fully covered pixel equals E(n·v, α) (averaged over the pixel).
// The furnace tests read fully covered pixels only, so they render with silhouette_boost = 1: a covered
// pixel is never a silhouette pixel, the boost only raises the partly covered pixels' counts (mc_adaptive.h;
// the mean the counts are scaled by is the pilot's, boost or not), and each pixel's random numbers are
// its own: every pixel checked here has the same bits as with the default boost of 16 (compared for both
// scenes and every lobe, 1620 pixels each), and the renders take 2.5-3.5x less time (issue 33).
TEST(ReferenceIntegrator, FurnaceMetalMatchesQuadrature) {
    // 24 px per sphere (default 64) so that 8192 spp fits a fast test. The expected value is averaged
    // over a 32x32 grid inside each pixel: near the silhouette n.v varies fast and a 4x4 grid alone is
    // off by up to 0.3 %.
    // 16384 spp: in a constant environment the windowed environment strategy (the default) competes with
    // the exact GGX sampling under MIS instead of helping it; the worst pixel at 8192 spp was 0.21 %
    // (0.196 % with the unwindowed distribution), noise, not bias (it halves with 4x the samples).
    TestSpec spec = reference_spec("furnace", "constant:1", 16384, 120, 24);
    spec.options.set("silhouette_boost", "1"); // the checked pixels are the same bits, in 1/3 of the time
    ReferenceRender r = render_reference_full(spec);
    Scene s = build_scene("furnace", {});
    const int W = r.result.image.cols, H = r.result.image.rows;
    ASSERT_EQ(W, 120);
    std::vector<AlbedoTable> tables;
    for (const auto& sp : s.spheres) tables.emplace_back(model::alpha_from_roughness(sp.material.roughness), 1.0);
    std::vector<double> mus;
    double worst[5] = {0, 0, 0, 0, 0};
    int checked = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int sph;
            if (!pixel_mu_grid(s, W, H, x, y, 32, mus, sph)) continue;
            double expect = 0;
            for (double mu : mus) expect += s.spheres[sph].material.roughness == 0 ? 1.0 : tables[sph](mu);
            expect /= mus.size();
            const auto& px = r.result.image.at<cv::Vec3f>(y, x);
            for (int c = 0; c < 3; ++c) {
                double rel = std::fabs(px[c] / expect - 1);
                worst[sph] = std::max(worst[sph], rel);
                ASSERT_LT(rel, 2e-3) << "pixel (" << x << "," << y << ") sphere " << sph << " got " << px[c] << " expected "
                                     << expect;
            }
            ++checked;
        }
    EXPECT_GT(checked, 5 * 200);
    for (int i = 0; i < 5; ++i) std::printf("furnace sphere r=%.2f: worst relative error %.5f\n", 0.25 * i, worst[i]);
}

// White dielectric in L = 1: the diffuse lobe alone is exactly 1 (white Lambert); the whole model is
// 1 + the F0 = 0.04 specular albedo (the model has no (1 − F) on the diffuse term).
// The earlier 0.26–0.41 % worst pixel (at 8192 spp, tolerance 0.6 %) was noise, not bias: the mean
// SIGNED error over each sphere's ~320 fully covered pixels is within ±1e-4 for the whole model and
// for the specular lobe alone (where a 0.3 % bias of the total would be a 10 % error of the F0 = 0.04
// lobe), for several seeds. Checked here: per-sphere mean signed error (bias) and worst pixel (noise).
TEST(ReferenceIntegrator, FurnaceDielectricIsLambertPlusSpecular) {
    Scene s = build_scene("furnace_dielectric", {});
    // 16384 spp for the Lambert-only render (was 4096): the windowed environment strategy follows the
    // dilated cosine and so competes with the exact cosine sampling in a constant environment; the worst
    // pixel at 4096 spp was 0.42 %.
    // silhouette_boost = 1: the checked (fully covered) pixels' bits are the default's (see the metal test).
    TestSpec diff = reference_spec("furnace_dielectric", "constant:1", 16384, 120, 24);
    diff.options.set("lobes", "diffuse");
    diff.options.set("silhouette_boost", "1");
    ReferenceRender rd = render_reference_full(diff);
    TestSpec all = reference_spec("furnace_dielectric", "constant:1", 8192, 120, 24);
    all.options.set("silhouette_boost", "1");
    ReferenceRender ra = render_reference_full(all);
    TestSpec spec_only = all;
    spec_only.options.set("lobes", "specular");
    ReferenceRender rs = render_reference_full(spec_only);
    const int W = ra.result.image.cols, H = ra.result.image.rows;
    std::vector<AlbedoTable> tables;
    for (const auto& sp : s.spheres)
        tables.emplace_back(model::alpha_from_roughness(sp.material.roughness), model::kDielectricF0);
    std::vector<double> mus;
    int checked = 0;
    double bias_all[5] = {0}, bias_spec[5] = {0}, worst_all[5] = {0}, worst_spec[5] = {0};
    int n[5] = {0};
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            int sph;
            if (!pixel_mu_grid(s, W, H, x, y, 32, mus, sph)) continue;
            double spec = 0;
            for (double mu : mus)
                spec += s.spheres[sph].material.roughness == 0 ? model::f_schlick(model::kDielectricF0, mu) : tables[sph](mu);
            spec /= mus.size();
            for (int c = 0; c < 3; ++c) {
                // 0.3 % (was 0.4 %): environment samples below the horizon make constant-environment renders noisy.
                ASSERT_NEAR(rd.result.image.at<cv::Vec3f>(y, x)[c], 1.0, 3e-3) << x << "," << y;
                // 0.4 % (was 0.6 %): worst pixel ~0.15-0.25 % at 8192 spp (noise: see the bias check below).
                double ea = ra.result.image.at<cv::Vec3f>(y, x)[c] / (1.0 + spec) - 1;
                double es = rs.result.image.at<cv::Vec3f>(y, x)[c] / spec - 1;
                ASSERT_NEAR(ea, 0.0, 4e-3) << x << "," << y << " sphere " << sph;
                // The specular lobe alone, relative to itself: 2 % (worst pixel ~0.7-1.1 % at r = 1, where
                // the lobe is widest and the F0 = 0.04 lobe's share of the samples smallest).
                ASSERT_NEAR(es, 0.0, 2e-2) << x << "," << y << " sphere " << sph;
                if (c == 1) {
                    bias_all[sph] += ea, bias_spec[sph] += es, ++n[sph];
                    worst_all[sph] = std::max(worst_all[sph], std::fabs(ea));
                    worst_spec[sph] = std::max(worst_spec[sph], std::fabs(es));
                }
            }
            ++checked;
        }
    EXPECT_GT(checked, 5 * 200);
    for (int i = 0; i < 5; ++i) {
        bias_all[i] /= n[i], bias_spec[i] /= n[i];
        // No bias: the mean signed error over the sphere is within a few standard errors of 0.
        EXPECT_LT(std::fabs(bias_all[i]), 3e-4) << "sphere " << i;
        EXPECT_LT(std::fabs(bias_spec[i]), 1e-3) << "sphere " << i;
        std::printf("dielectric furnace r=%.2f: whole model mean %+.5f worst %.5f; specular lobe mean %+.5f worst %.5f\n",
                    0.25 * i, bias_all[i], worst_all[i], bias_spec[i], worst_spec[i]);
    }
}

namespace {
// Black panorama with a (2k+1)² block of radiance L centred on the pixel that direction d falls in.
Environment patch_env(const float d[3], int k, float L, double& solid_angle) {
    Environment e;
    e.spec = "patch";
    e.equirect = cv::Mat(256, 512, CV_32FC3, cv::Scalar(0, 0, 0));
    float u, v;
    direction_to_uv(d, u, v);
    int ci = int(u * 512), cj = int(v * 256);
    solid_angle = 0;
    for (int j = cj - k; j <= cj + k; ++j) {
        for (int i = ci - k; i <= ci + k; ++i) e.equirect.at<cv::Vec3f>(j, (i + 512) % 512) = {L, L, L};
        solid_angle += (2 * kPi / 512) * (std::cos(j * kPi / 256) - std::cos((j + 1) * kPi / 256)) * (2 * k + 1);
    }
    return e;
}
} // namespace

// A small bright patch in a black environment: the pixel whose mirror direction points at it reads
// f(l, v)·(n·l)·L·Ω (small-light approximation).
TEST(ReferenceIntegrator, SmallPatchMatchesAnalyticBrdf) {
    const int W = 64, H = 64, px = 40, py = 22;
    for (double rough : {0.5, 0.35}) {
        TestSpec spec = reference_spec("sphere", "patch", 256, W, H);
        spec.options.set("roughness", std::to_string(rough));
        spec.options.set("metallic", "1");
        spec.options.set("base_color", "1");
        Scene s = build_scene("sphere", spec.options);
        Vec3f o, d;
        camera_ray(s, W, H, px + 0.5, py + 0.5, o, d);
        Hit h = intersect(s, o, d);
        ASSERT_TRUE(h.hit);
        double n[3] = {h.normal.x, h.normal.y, h.normal.z}, v[3] = {-d.x, -d.y, -d.z};
        double nv = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
        float l[3];
        for (int i = 0; i < 3; ++i) l[i] = float(2 * nv * n[i] - v[i]);
        double omega;
        Environment env = patch_env(l, 1, 1000.0f, omega);
        // The patch's centre direction (its centre pixel), for the analytic value f·(n·l)·L·Ω, averaged
        // over a 4x4 grid of positions inside the camera pixel (the normal varies across the pixel).
        float u, vv, lc[3];
        direction_to_uv(l, u, vv);
        uv_to_direction((int(u * 512) + 0.5f) / 512, (int(vv * 256) + 0.5f) / 256, lc);
        double a = model::alpha_from_roughness(rough), f = 0;
        for (int sj = 0; sj < 4; ++sj)
            for (int si = 0; si < 4; ++si) {
                Vec3f o2, d2;
                camera_ray(s, W, H, px + (si + 0.5) / 4, py + (sj + 0.5) / 4, o2, d2);
                Hit h2 = intersect(s, o2, d2);
                double n2[3] = {h2.normal.x, h2.normal.y, h2.normal.z}, v2[3] = {-d2.x, -d2.y, -d2.z};
                double nv2 = n2[0] * v2[0] + n2[1] * v2[1] + n2[2] * v2[2];
                double nl = n2[0] * lc[0] + n2[1] * lc[1] + n2[2] * lc[2];
                double hv[3] = {lc[0] + v2[0], lc[1] + v2[1], lc[2] + v2[2]};
                double hl = std::sqrt(hv[0] * hv[0] + hv[1] * hv[1] + hv[2] * hv[2]);
                double nh = (n2[0] * hv[0] + n2[1] * hv[1] + n2[2] * hv[2]) / hl;
                double vh = (v2[0] * hv[0] + v2[1] * hv[1] + v2[2] * hv[2]) / hl;
                f += model::d_ggx(nh, a) * model::v_smith_ggx_correlated(nv2, nl, a) * model::f_schlick(1.0, vh) * nl / 16;
            }
        double nl = 1; // folded into f above
        double expect = f * nl * 1000.0 * omega;
        RenderResult r = render_reference(spec, env);
        double got = r.image.at<cv::Vec3f>(py, px)[1];
        EXPECT_NEAR(got / expect, 1.0, 0.03) << "roughness " << rough << " got " << got << " expected " << expect;
    }
    // Mirror (r = 0, F0 = 1): a patch wider than the pixel's reflected footprint reads exactly L.
    {
        TestSpec spec = reference_spec("sphere", "patch", 64, W, H);
        spec.options.set("roughness", "0");
        spec.options.set("metallic", "1");
        Scene s = build_scene("sphere", spec.options);
        Vec3f o, d;
        camera_ray(s, W, H, px + 0.5, py + 0.5, o, d);
        Hit h = intersect(s, o, d);
        double n[3] = {h.normal.x, h.normal.y, h.normal.z}, v[3] = {-d.x, -d.y, -d.z};
        double nv = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
        float l[3];
        for (int i = 0; i < 3; ++i) l[i] = float(2 * nv * n[i] - v[i]);
        double omega;
        Environment env = patch_env(l, 12, 1000.0f, omega);
        RenderResult r = render_reference(spec, env);
        EXPECT_NEAR(r.image.at<cv::Vec3f>(py, px)[0], 1000.0, 1e-3);
        EXPECT_NEAR(r.image.at<cv::Vec3f>(0, 0)[0], 0.0, 0.0); // background is black
    }
}

TEST(ReferenceIntegrator, DeterministicAcrossThreadsAndRuns) {
    TestSpec spec = reference_spec("roughness_sweep", "sky_sun", 8, 176, 32);
    spec.options.set("threads", "1");
    RenderResult a = render_reference(spec);
    spec.options.set("threads", "2");
    RenderResult b = render_reference(spec);
    RenderResult c = render_reference(spec);
    ASSERT_EQ(a.image.size(), b.image.size());
    ASSERT_TRUE(a.image.isContinuous() && b.image.isContinuous() && c.image.isContinuous());
    size_t bytes = a.image.total() * a.image.elemSize();
    EXPECT_EQ(std::memcmp(a.image.data, b.image.data, bytes), 0);
    EXPECT_EQ(std::memcmp(b.image.data, c.image.data, bytes), 0);
    // A different seed gives a different image.
    spec.options.set("seed", "5");
    RenderResult d = render_reference(spec);
    EXPECT_NE(std::memcmp(a.image.data, d.image.data, bytes), 0);
}

TEST(ReferenceIntegrator, ResultAndProvenance) {
    TestSpec spec = reference_spec("sphere", "studio", 4, 32, 32);
    spec.options.set("env_rotation", "45");
    RenderResult r = render_reference(spec);
    EXPECT_EQ(r.image.type(), CV_32FC3);
    EXPECT_EQ(r.image.cols, 32);
    ASSERT_EQ(r.timings.size(), 1u);
    EXPECT_EQ(r.timings[0].name, "reference_cpu");
    EXPECT_FALSE(r.timings[0].gpu);
    EXPECT_EQ(r.provenance["method"], "reference");
    EXPECT_EQ(r.provenance["spp"], 4);
    EXPECT_EQ(r.provenance["env"]["spec"], "studio");
    EXPECT_EQ(r.provenance["env"]["content_hash"], load_environment("studio").content_hash);
    EXPECT_FLOAT_EQ(r.provenance["env"]["rotation_deg"].get<float>(), 45.0f);
    EXPECT_GT(r.texture_fetches_per_pixel, 1.0);
    EXPECT_LT(r.texture_fetches_per_pixel, 2.0 * 4 + 1e-9);
    EXPECT_THROW(render_reference(reference_spec("nope", "studio", 4)), UsageError);
}

TEST(ReferenceIntegrator, NoiseFloorShrinksWithSpp) {
    TestSpec spec = reference_spec("sphere", "studio", 0, 48, 48);
    NoiseFloor lo = measure_noise_floor(spec, 16);
    NoiseFloor hi = measure_noise_floor(spec, 256);
    EXPECT_GT(lo.relative_rmse, 0);
    EXPECT_GT(lo.covered_pixels, 1000);
    EXPECT_LT(hi.relative_rmse, lo.relative_rmse / 3);
    std::printf("sphere/studio 48x48 noise floor: spp 16 -> %.4f, spp 256 -> %.4f\n", lo.relative_rmse, hi.relative_rmse);
}

// The sub-pixel positions are keyed by pixel_pattern, not by the lighting seed: two seeds cover every
// pixel identically (so the noise floor is lighting noise only), and the pattern's own error — a
// 256-point quadrature of the pixel footprint — is small: two patterns give almost the same coverage,
// and on the mirror sphere (lobes=specular, r = 0: the shading is deterministic per position, so the
// difference is the pattern error alone) almost the same image.
// The mirror's shading is deterministic per position, so one lighting sample a position (adaptive = 0) gives
// the image that 8192 spp (2048 positions x 4 and the adaptive counts: up to 64 at the silhouette) gave,
// repeating no lookup (issue 33: 20 s of CPU -> 2 s; the same figures).
TEST(ReferenceIntegrator, PixelPatternErrorIsSmall) {
    TestSpec spec = reference_spec("sphere", "studio", 2048, 64, 64);
    spec.options.set("positions", "2048");
    spec.options.set("adaptive", "0");
    spec.options.set("roughness", "0");
    spec.options.set("metallic", "1");
    spec.options.set("lobes", "specular");
    ReferenceRender a = render_reference_full(spec);
    spec.options.set("seed", "1");
    ReferenceRender b = render_reference_full(spec);
    spec.options.set("pixel_pattern", "1");
    ReferenceRender c = render_reference_full(spec);
    ASSERT_EQ(a.result.provenance["positions"], 2048);
    ASSERT_EQ(cv::norm(a.coverage, b.coverage, cv::NORM_INF), 0.0);
    // Mirror: no lighting noise at all, so seeds 0 and 1 agree exactly.
    EXPECT_EQ(cv::norm(a.result.image, b.result.image, cv::NORM_INF), 0.0);
    double sum_d = 0, edge = 0, cov_a = 0, cov_c = 0;
    for (int y = 0; y < a.coverage.rows; ++y)
        for (int x = 0; x < a.coverage.cols; ++x) {
            double ca = a.coverage.at<float>(y, x), cc = c.coverage.at<float>(y, x);
            cov_a += ca, cov_c += cc;
            if ((ca > 0 && ca < 1) || (cc > 0 && cc < 1)) sum_d += std::fabs(ca - cc), ++edge;
        }
    ASSERT_GT(edge, 50);
    EXPECT_LT(sum_d / edge, 2e-3);         // mean |Δcoverage| of silhouette pixels
    EXPECT_NEAR(cov_c / cov_a, 1.0, 2e-4); // total covered area
    // The pattern error of the worst case (sharp light edges seen in a mirror) is well below the
    // 0.5 % relative-RMSE criterion the noise floor is held to.
    double rel = relative_rmse(a.result.image, c.result.image, a.coverage);
    EXPECT_LT(rel, 2.5e-3);
    std::printf("pixel pattern 0 vs 1 (2048 positions): mean |dcoverage| on %d silhouette pixels %.5f, area ratio "
                "%.6f, mirror-sphere relative RMSE %.5f\n",
                int(edge), sum_d / edge, cov_c / cov_a, rel);
}
} // namespace test_reference_integrator
