// The quadrature truth end to end: furnace identities, constant-environment closed forms, the stated
// bound against a much finer solution, agreement with the Monte Carlo integrator, determinism, the
// bumpy sphere through Renderer::render, and the golden's sidecar.
#include "renderers/reference/quadrature/truth_renderer.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "image_io/image_io.h"
#include "renderers/reference/quadrature/footprint.h"
#include "renderers/reference/quadrature/sphere_view.h"
#include "renderers/reference/reference.h"
#include "renderers/renderer.h"

using namespace iblcheck;
using namespace iblcheck::truth;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace truth_renderer_test {

namespace {
TestSpec spec_of(const std::string& scene, const std::string& env, int w = 0, int h = 0) {
    TestSpec s;
    s.scene = scene, s.env = env, s.method = "reference", s.width = w, s.height = h;
    return s;
}
cv::Vec3f px(const cv::Mat& m, int x, int y) { return m.at<cv::Vec3f>(y, x); }
} // namespace

// White furnace, F0 = 1 (material_model.h): the centre pixel of each sphere sees normal incidence
// (n·v > 0.9998 over it), where E = 0.91581 at r = 0.5 and 1 − ln 2 at r = 1; a white Lambert sphere
// reflects exactly 1 everywhere, plus its F0 = 0.04 specular albedo.
TEST(TruthRenderer, FurnaceIdentities) {
    TruthRender m = render_truth(spec_of("furnace", "constant:1"), load_environment("constant:1"));
    // 320x64, spheres of 64 px cells centred at x = 32 + 64 i, y = 32 (pixel 31.5..32.5 is the centre).
    EXPECT_NEAR(px(m.result.image, 160, 31)[1] / 2 + px(m.result.image, 159, 32)[1] / 2, 0.91581, 2e-4);           // r = 0.5
    EXPECT_NEAR(px(m.result.image, 288, 31)[1] / 2 + px(m.result.image, 287, 32)[1] / 2, 1 - std::log(2.0), 2e-4); // r = 1
    EXPECT_NEAR(px(m.result.image, 32, 32)[0], 1.0, 1e-4); // mirror, F0 = 1
    TestSpec d = spec_of("furnace_dielectric", "constant:1");
    d.options.set("lobes", "diffuse");
    TruthRender l = render_truth(d, load_environment("constant:1"));
    // Within the finer level's per-pixel tolerance (5e-4 since finer() halves the tolerances; measured:
    // 2.4e-4 at worst).
    const double tol = TruthAccuracy{}.finer().pixel_tolerance;
    for (int x = 20; x < 300; x += 7)
        for (int y = 20; y < 44; y += 5) {
            if (l.fine.coverage.at<float>(y, x) >= 1) {
                EXPECT_NEAR(px(l.result.image, x, y)[2], 1.0, tol) << x << "," << y;
            }
        }
    std::printf("furnace centre pixels: r=0.5 %.5f, r=1 %.5f\n", px(m.result.image, 160, 31)[1], px(m.result.image, 288, 31)[1]);
}

// A mirror in a constant environment c: each pixel is c·(1/|pixel|)∫ F(n·v) over pixel ∩ disc — checked
// against the footprint integral of F alone (exact coverage, the same closed forms) — and a Lambert
// sphere is c·albedo·coverage.
TEST(TruthRenderer, ConstantEnvironmentClosedForms) {
    TestSpec s = spec_of("sphere", "constant:0.5", 24, 24);
    s.options.set("roughness", "0"), s.options.set("metallic", "1"), s.options.set("base_color", "0.8");
    TruthRender r = render_truth(s, load_environment("constant:0.5"));
    const Scene scene = build_scene("sphere", s.options);
    const SphereView sv(scene, 0, 24, 24, Lobes::all);
    PointShader F = [&](double x, double y, double out[3]) {
        const V3 n = sv.normal(x, y);
        out[0] = out[1] = out[2] = model::f_schlick(0.8, std::max(dot(n, sv.view()), kMinNdotV));
    };
    // Independently: a 2000x2000 midpoint grid over the pixel (F's square-root singularity at the rim is
    // integrable: the grid's error there is ~1e-5 of the pixel), on the centre, the rim and in between.
    auto brute = [&](int x, int y) {
        const int n = 2000;
        double sum = 0;
        for (int b = 0; b < n; ++b)
            for (int a = 0; a < n; ++a) {
                const double xx = x + (a + 0.5) / n, yy = y + (b + 0.5) / n;
                const Disc& d = sv.disc();
                if ((xx - d.cx) * (xx - d.cx) + (yy - d.cy) * (yy - d.cy) > d.r * d.r) continue;
                double f[3];
                F(xx, yy, f);
                sum += f[0];
            }
        return sum / (double(n) * n);
    };
    for (auto [x, y] : {std::pair{4, 3}, {12, 12}, {1, 12}, {12, 1}, {20, 6}, {7, 21}, {16, 2}}) {
        const double want = 0.5 * brute(x, y);
        EXPECT_NEAR(px(r.result.image, x, y)[0], want, 3e-4 * want + 2e-6) << x << "," << y;
    }
    TestSpec d = spec_of("sphere", "constant:0.5", 24, 24);
    d.options.set("lobes", "diffuse"), d.options.set("base_color", "0.6");
    TruthRender l = render_truth(d, load_environment("constant:0.5"));
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x)
            ASSERT_NEAR(px(l.result.image, x, y)[1], 0.3 * l.fine.coverage.at<float>(y, x), 1e-4) << x << "," << y;
}

namespace {
// The stated bound — the difference between the two levels — bounds the finer level's error against a
// much finer solution (every tolerance / 16, guard / 4), on a small sweep under the sun.
void expect_bound_holds(const Scene& scene, int W, int H) {
    const EnvPyramid env(load_environment("sky_sun"));
    TruthAccuracy acc;
    const TruthImage coarse = render_truth_level(scene, W, H, env, "t1", Lobes::all, acc, 2);
    const TruthImage fine = render_truth_level(scene, W, H, env, "t1", Lobes::all, acc.finer(), 2);
    const TruthImage best = render_truth_level(scene, W, H, env, "t1", Lobes::all, acc.finer().finer(), 2);
    const TruthBound bound = compare_levels(coarse, fine, scene), actual = compare_levels(fine, best, scene);
    EXPECT_LT(actual.relative_rmse, bound.relative_rmse);
    EXPECT_LT(actual.worst, bound.worst);
    // Per sphere the bound is an estimate, not a guarantee: with finer() halving each control the finer
    // level's error was measured at up to 1.63x the sphere's bound (metal r = 0.3: 0.080 % against a
    // stated 0.049 %), so a sphere may be under-stated by 2x at most; the image's bound above holds as is.
    for (size_t s = 0; s < scene.spheres.size(); ++s)
        EXPECT_LE(actual.spheres[s].relative_rmse, 2.0 * bound.spheres[s].relative_rmse + 1e-5) << scene.labels[s];
    std::printf("%zu spheres: bound (coarse vs fine): rel. RMSE %.5f worst %.5f; actual (fine vs 4x finer): %.5f, %.5f\n",
                scene.spheres.size(), bound.relative_rmse, bound.worst, actual.relative_rmse, actual.worst);
}
} // namespace

// Every other sphere of the sweep (metal r = 0.1, 0.3 (the sphere the bound under-states most), ..., 0.9;
// dielectric r = 0, 0.2, ..., 1): half the time of the whole sweep, which runs with the `slow` label
// (issue 33: 79 s of CPU at load 5, the default run's fourth longest test).
TEST(TruthRenderer, RefinementBoundBoundsTheErrorAgainstAFinerSolution) {
    const Scene sweep = build_scene("roughness_sweep", {});
    Scene half = sweep;
    half.spheres.clear(), half.labels.clear();
    for (size_t i = 0; i < sweep.spheres.size(); ++i)
        if ((i % 11) % 2 == (i < 11 ? 1u : 0u)) half.spheres.push_back(sweep.spheres[i]), half.labels.push_back(sweep.labels[i]);
    ASSERT_EQ(half.spheres.size(), 11u);
    ASSERT_EQ(half.labels[1], "metal r=0.3");
    expect_bound_holds(half, 132, 24);
}
TEST(TruthRenderer, RefinementBoundBoundsTheErrorOnTheWholeSweep) {
    expect_bound_holds(build_scene("roughness_sweep", {}), 132, 24);
}

// The Monte Carlo integrator agrees within its own noise: per sphere, the image means differ by less
// than 1 % (a 16x16 px sphere at 2048 spp has ~0.1-0.3 % noise in its mean), and the relative RMSE
// between the two images is about the Monte Carlo render's own (√½ of its between-seeds noise floor).
// The Monte Carlo image compared is the noise floor's first render (seed 0, 2048 spp: the image a
// render_reference_full of the same spec gives, bit for bit), not a third render (issue 33). The truth
// is its finer level alone, the truth's image (DeterministicAcrossThreadsAndAnnotated checks that they
// are the same): the coarse level, a third of the truth's time, only states the bound.
TEST(TruthRenderer, AgreesWithTheMonteCarloIntegrator) {
    TestSpec s = spec_of("roughness_sweep", "studio", 176, 32);
    const Environment e = load_environment("studio");
    const TruthImage t = render_truth_level(build_scene("roughness_sweep", {}), 176, 32, EnvPyramid(e), "studio-fine", Lobes::all,
                                            TruthAccuracy{}.finer(), 0);
    const NoiseFloor nf = measure_noise_floor(s, 2048);
    ASSERT_EQ(nf.seed_a, 0);
    ASSERT_EQ(nf.provenance_a["spp"], 2048);
    const cv::Mat& mc = nf.image_a;
    for (int cy = 0; cy < 2; ++cy)
        for (int cx = 0; cx < 11; ++cx) {
            const cv::Rect rc(cx * 16, cy * 16, 16, 16);
            const cv::Scalar a = cv::sum(t.image(rc)), b = cv::sum(mc(rc));
            EXPECT_NEAR((a[0] + a[1] + a[2]) / (b[0] + b[1] + b[2]), 1.0, 1e-2) << "sphere " << cx << "," << cy;
        }
    const double rel = relative_rmse(t.image, mc, nf.coverage);
    EXPECT_LT(rel, 1.2 * nf.relative_rmse);
    std::printf("truth vs Monte Carlo (2048 spp): relative RMSE %.4f; Monte Carlo noise floor between seeds %.4f\n", rel,
                nf.relative_rmse);
}

// Determinism: the sweep's coarse level on 2 threads and on 1, bit for bit and with the same counts
// (the finer level is the same code, render_truth_level, with tighter tolerances). Each has its own
// environment key, so neither reuses the other's normal tables. The annotations (a bound per sphere)
// and the two levels come from render_truth of the five furnace spheres in a constant environment:
// rendered for the whole sweep under the sun, its two levels were three times the coarse level's
// time, most of this test's 32 s of CPU (issue 33).
TEST(TruthRenderer, DeterministicAcrossThreadsAndAnnotated) {
    const Environment env = load_environment("sky_sun");
    const EnvPyramid pyramid(env);
    const Scene sweep = build_scene("roughness_sweep", {});
    const TruthImage two =
        render_truth_level(sweep, 88, 16, pyramid, "determinism-on-two-threads", Lobes::all, TruthAccuracy{}, 2);
    const TruthImage one =
        render_truth_level(sweep, 88, 16, pyramid, "determinism-on-one-thread", Lobes::all, TruthAccuracy{}, 1);
    const cv::Mat &a = one.image, &c = two.image;
    ASSERT_TRUE(a.isContinuous() && c.isContinuous());
    ASSERT_EQ(a.size(), c.size());
    EXPECT_EQ(std::memcmp(a.data, c.data, a.total() * a.elemSize()), 0);
    EXPECT_EQ(one.evaluations, two.evaluations);
    EXPECT_EQ(one.footprint_points, two.footprint_points);

    TestSpec s = spec_of("furnace", "constant:0.5", 80, 16);
    s.options.set("threads", "2");
    const TruthRender r = render_truth(s, load_environment("constant:0.5"));
    const RenderResult& b = r.result;
    EXPECT_GT(cv::norm(r.coarse.image, r.fine.image, cv::NORM_INF), 0.0); // two levels, two images
    EXPECT_EQ(cv::norm(b.image, r.fine.image, cv::NORM_INF), 0.0);        // the image is the finer level
    EXPECT_EQ(b.provenance["integrator"], "quadrature");
    EXPECT_EQ(b.provenance["deterministic"], true);
    ASSERT_TRUE(b.provenance["error_bound"].contains("per_sphere"));
    const size_t spheres = build_scene("furnace", s.options).spheres.size();
    ASSERT_GT(spheres, 1u);
    EXPECT_EQ(b.provenance["error_bound"]["per_sphere"].size(), spheres);
    EXPECT_FALSE(uses_quadrature([] {
        TestSpec m;
        m.options.set("spp", "64");
        return m;
    }()));
}

// bumpy_sphere through the method dispatcher (no GPU is touched for method=reference): frames differ,
// the image is deterministic, and the bumps' average brightness stays near the smooth sphere's.
TEST(TruthRenderer, BumpySphereFramesThroughTheRenderer) {
    Renderer renderer;
    // 16x16, roughness 0.5 and a loose tolerance: what is checked is the dispatch, the frames and
    // determinism, not the accuracy (32x32 at the scene's roughness and the default tolerance took 333 s of
    // a loaded 2-core machine, most of it the normal table over the bumps' wide cone of normals).
    TestSpec s = spec_of("bumpy_sphere", "studio", 16, 16);
    s.options.set("truth_tolerance", "0.01");
    s.options.set("roughness", "0.5");
    s.options.set("frame", "0");
    const RenderResult f0 = renderer.render(s);
    s.options.set("frame", "3");
    const RenderResult f3 = renderer.render(s);
    const RenderResult f3b = renderer.render(s);
    EXPECT_GT(cv::norm(f0.image, f3.image, cv::NORM_INF), 1e-3);
    EXPECT_EQ(cv::norm(f3.image, f3b.image, cv::NORM_INF), 0.0);
    EXPECT_EQ(f3.provenance["integrator"], "quadrature");
    TestSpec smooth = s;
    smooth.options.set("bump_amplitude", "0");
    const cv::Scalar mb = cv::mean(f3.image), ms = cv::mean(renderer.render(smooth).image);
    EXPECT_NEAR(mb[1] / ms[1], 1.0, 0.15);
    std::printf("bumpy_sphere 16x16: frame 3 mean %.4f, smooth sphere %.4f; bound rel. RMSE %.4f\n", mb[1], ms[1],
                f3.provenance["error_bound"]["relative_rmse"].get<double>());
}

// A mirror sphere with F0 = 1 (F = 1 at every angle) under an orthographic camera maps image area to
// solid angle with a constant Jacobian: dA = (R²/4)·dω (the projected area R²(n·v)dω_n over the
// half-vector Jacobian dω = 4(n·v)dω_n), so the sphere's pixels sum to (R²/4)·∫L dω for any
// environment — here a random-texel one, the worst case for the footprint's adaptive rule. The footprint
// stops at the variation bound's depth (shade_pixel): ~(4/3)·4^depth points a pixel plus the rim's polar rules; without that
// cap the texel edges drove it to tens of thousands more (measured: 1.4e5 a pixel on Blender's forest).
TEST(TruthRenderer, MirrorPixelsSumToTheEnvironmentIntegralWithinTheDepthCap) {
    Environment e;
    e.spec = "random-texels", e.content_hash = "random-texels";
    e.equirect = cv::Mat(128, 256, CV_32FC3);
    cv::randu(e.equirect, cv::Scalar::all(0), cv::Scalar::all(4));
    const EnvPyramid pyramid(e);
    OptionMap o;
    o.set("roughness", "0"), o.set("metallic", "1"), o.set("base_color", "1");
    const Scene scene = build_scene("sphere", o);
    const TruthAccuracy acc;
    const TruthImage img = render_truth_level(scene, 32, 32, pyramid, e.content_hash, Lobes::all, acc, 2);
    const double r2 = cv::sum(img.coverage)[0] / kPi; // exact coverage: Σ = πR²
    double env_integral[3] = {0, 0, 0};
    for (int j = 0; j < pyramid.height(0); ++j)
        for (int i = 0; i < pyramid.width(0); ++i)
            for (int q = 0; q < 3; ++q) env_integral[q] += pyramid.cell(0, i, j).L[q];
    const cv::Scalar sum = cv::sum(img.image);
    for (int q = 0; q < 3; ++q) EXPECT_NEAR(sum[q] / (r2 / 4 * env_integral[q]), 1.0, 2e-4) << "channel " << q;
    const double covered = cv::countNonZero(img.coverage > 0);
    const double per_pixel = double(img.footprint_points) / covered;
    std::printf("mirror sphere, R = %.2f px: %.0f footprint points a covered pixel; Σ pixels / (R²/4 ∫L) = %.6f\n", std::sqrt(r2),
                per_pixel, sum[1] / (r2 / 4 * env_integral[1]));
    EXPECT_LT(per_pixel, 2 * std::pow(4.0, acc.bound_depth)); // measured 7375 (66006 without the cap)
}
} // namespace truth_renderer_test
