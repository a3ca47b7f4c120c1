// The quadrature truth renderer (truth_renderer.h): per pixel, per sphere whose silhouette it touches,
// the footprint integral (footprint.h) of the shading (lobe_quadrature.h), at two refinement levels.
#include "renderers/reference/quadrature/truth_renderer.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <mutex>

#include <fmt/format.h>

#include "kernel/errors.h"
#include "kernel/parallel_for.h"
#include "renderers/option_table.h"
#include "renderers/reference/quadrature/footprint.h"
#include "renderers/reference/quadrature/lobe_quadrature.h"
#include "renderers/reference/quadrature/normal_table.h"
#include "renderers/reference/quadrature/sphere_view.h"

namespace iblcheck::truth {

TruthAccuracy TruthAccuracy::finer() const {
    // Every control halves (the guard by √2: cells are 2-D). Measured on the studio sweep against the
    // previous finer level (tolerances / 4, guard / 2; CONVERGENCE.md): the coarse level is within mean
    // FLIP 0.00106 of it and this finer one within 0.00045, for 46 + 93 s of CPU instead of 58 + 186 s.
    TruthAccuracy f = *this;
    f.pixel_tolerance /= 2, f.env_tolerance /= 2, f.table_tolerance /= 2, f.kappa /= std::sqrt(2.0);
    f.bound_depth += 1;
    return f;
}

TruthAccuracy TruthAccuracy::temporal() {
    TruthAccuracy a;
    // Measured on bumpy_sphere frame 0 (CONVERGENCE.md, "The temporal truth"): the table is built once for
    // all frames, so its controls are tight (table 0.1 left the sun's spots unresolved: 17 % between
    // levels; 3.125e-3: 1.0 % under sky_sun, 0.34 % under studio); a frame's cost is its footprint,
    // 2^-5 px squares at most (the variation bound's depth, shade_pixel).
    a.pixel_tolerance = 1e-2, a.env_tolerance = 1.25e-3, a.table_tolerance = 3.125e-3, a.kappa = std::sqrt(2.0);
    a.bound_depth = 5;
    return a;
}

nlohmann::json TruthAccuracy::json() const {
    return {{"pixel_tolerance", pixel_tolerance},
            {"env_tolerance", env_tolerance},
            {"table_tolerance", table_tolerance},
            {"floor_of_mean_radiance", floor},
            {"kappa", kappa},
            {"bound_depth", bound_depth}};
}

namespace {

QuadratureParams quadrature_params(const TruthAccuracy& acc, const EnvPyramid& env) {
    QuadratureParams qp;
    qp.tolerance = acc.env_tolerance, qp.floor = acc.floor * env.mean_radiance(), qp.kappa = acc.kappa;
    return qp;
}

// The sphere's normal table for the lobes other than a mirror's delta (normal_table.h). Tables are
// kept across renders — a temporal sequence's frames share one per level — the last few, keyed by
// everything they depend on.
std::shared_ptr<const NormalTable> normal_table(const EnvPyramid& env, const std::string& env_key, const SphereView& sv,
                                                const MaterialLobe& L, const TruthAccuracy& acc, int threads,
                                                const Progress& progress) {
    static std::mutex m;
    static std::vector<std::pair<std::string, std::shared_ptr<const NormalTable>>> cache;
    const V3 v = sv.view(), r = sv.right(), u = sv.up();
    const std::string key =
        fmt::format("{}|{}|{}|{},{},{}|{},{},{}|{},{},{}|{},{},{}|{}|{}", env_key, L.alpha,
                    int(L.diffuse) + 2 * int(L.specular) + 4 * int(L.split_sum), L.f0[0], L.f0[1], L.f0[2], L.kd[0], L.kd[1],
                    L.kd[2], v.x, v.y, v.z, r.x, r.y, r.z, acc.json().dump(), int(sv.sphere().bump_amplitude > 0));
    {
        std::lock_guard<std::mutex> lock(m);
        for (auto& [k, t] : cache)
            if (k == key) return t;
    }
    TableParams tp;
    tp.tolerance = acc.table_tolerance, tp.floor = acc.floor * env.mean_radiance(), tp.kappa = acc.kappa;
    // A pixel's footprint in normal space: 1/R rad at the disc's centre; bumps sweep ~0.5 rad per pixel.
    tp.footprint = 1 / sv.disc().r;
    if (sv.sphere().bump_amplitude > 0)
        tp.min_nv = -0.5, tp.weight_offset = 0.3, tp.footprint = 0.3;
    else
        tp.min_nv = -0.02; // lookups on the silhouette stay inside
    auto t = std::make_shared<const NormalTable>(env, L, v, r, u, tp, quadrature_params(acc, env), threads, progress);
    std::lock_guard<std::mutex> lock(m);
    cache.emplace_back(key, t);
    if (cache.size() > 8) cache.erase(cache.begin());
    return t;
}

// One sphere's footprint integrals for one pixel at one level. The mirror's delta lobe is integrated
// directly (one lookup per point, the environment's full detail; its variation bound — the reflected
// radiance's range over a square's reflection cone — drives the refinement); everything else through
// the sphere's normal table (lookups), with the table's range over a square's cone of normals as the
// variation bound.
void shade_pixel(const SphereView& sv, const EnvPyramid& env, const NormalTable* table, const TruthAccuracy& acc, int px, int py,
                 double rgb[3], double& coverage, long& points) {
    FootprintParams fp;
    fp.tolerance = acc.pixel_tolerance;
    fp.bound_depth = acc.bound_depth;
    fp.floor = acc.floor * env.mean_radiance();
    const MaterialLobe& lobe = sv.lobe();
    coverage = 0;
    if (lobe.mirror && lobe.specular) {
        PointShader g = [&](double x, double y, double out[3]) { sv.mirror(env, x, y, out); };
        // No square below the variation bound's depth: there the bilinear radiance is smooth within a
        // square and the one-point rule is already accurate, but the tolerance, shared among thousands of
        // squares, kept splitting the texel edges (Blender forest, metal r = 0 of the sweep: 138k points
        // a pixel, 13x the time, to move the pixels by a relative RMSE of 0.012 %). The finer level goes
        // one level deeper, so the stated bound includes this.
        fp.max_depth = acc.bound_depth;
        VariationBound b = [&](double x0, double y0, double s) { return sv.mirror_variation(env, x0, y0, s); };
        const PixelIntegral pi = integrate_pixel(sv.disc(), px, py, g, &b, fp);
        for (int q = 0; q < 3; ++q) rgb[q] += pi.rgb[q];
        coverage = pi.coverage;
        points += pi.evaluations;
    }
    if (table) {
        const bool bumps = sv.sphere().bump_amplitude > 0;
        PointShader g = [&](double x, double y, double out[3]) { table->lookup(sv.bumped_normal(x, y), out); };
        // Bumps put a pixel's worth of normals into sub-pixel squares: their variation bound finds the
        // sun in a square; a smooth sphere's squares see a smooth table, the indicator suffices.
        VariationBound b = [&](double x0, double y0, double s) {
            V3 n;
            const double radius = sv.normal_cone(x0, y0, s, n);
            return table->variation(n, radius);
        };
        fp.min_depth = bumps ? 2 : 1;              // bumps: a period is ~2 px
        if (bumps) fp.max_depth = acc.bound_depth; // as the mirror's (above): the finer level goes one deeper
        const PixelIntegral pi = integrate_pixel(sv.disc(), px, py, g, bumps ? &b : nullptr, fp);
        for (int q = 0; q < 3; ++q) rgb[q] += pi.rgb[q];
        coverage = pi.coverage;
        points += pi.evaluations;
    }
}

} // namespace

TruthImage render_truth_level(const Scene& scene, int W, int H, const EnvPyramid& env, const std::string& env_key, Lobes lobes,
                              const TruthAccuracy& acc, int threads, const Progress& progress, SplitSum split_sum) {
    auto t0 = std::chrono::steady_clock::now();
    std::vector<SphereView> views = sphere_views(scene, W, H, lobes);
    for (SphereView& v : views) v.set_split_sum(split_sum);
    // The spheres' normal tables first: most of the level's work (half of its progress).
    std::vector<std::shared_ptr<const NormalTable>> tables(views.size());
    long table_evals = 0, table_nodes = 0;
    for (size_t s = 0; s < views.size(); ++s) {
        MaterialLobe rest = views[s].lobe();
        if (rest.mirror) rest.specular = false; // the delta is integrated directly
        if (!rest.diffuse && !rest.glossy()) continue;
        Progress p;
        if (progress) p = [&, s](double f) { progress(0.5 * (double(s) + f) / double(views.size())); };
        const auto ts = std::chrono::steady_clock::now();
        tables[s] = normal_table(env, env_key, views[s], rest, acc, threads, p);
        table_evals += tables[s]->evaluations(), table_nodes += tables[s]->nodes();
        if (std::getenv("IBLCHECK_TRUTH_VERBOSE")) // per-sphere cost (CONVERGENCE.md's measurements)
            fmt::print(stderr, "sphere {} ({}): table {} nodes, {:.0f} evaluations/node, {:.2f} s\n", s,
                       s < scene.labels.size() ? scene.labels[s] : "", tables[s]->nodes(),
                       double(tables[s]->evaluations()) / double(std::max(1L, tables[s]->nodes())),
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count());
    }
    const double table_share = 0.5;
    TruthImage out;
    out.image = cv::Mat(H, W, CV_32FC3, cv::Scalar(0, 0, 0));
    out.coverage = cv::Mat(H, W, CV_32FC1, cv::Scalar(0));
    out.sphere = cv::Mat(H, W, CV_32SC1, cv::Scalar(-1));
    // Work per row, for the progress fraction: covered pixels (the background costs nothing).
    std::vector<long> row_work(size_t(H), 0);
    long total_work = 0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x)
            for (const SphereView& sv : views)
                if (sv.touches(x, y)) ++row_work[size_t(y)];
        total_work += row_work[size_t(y)];
    }
    std::atomic<long> evals{0}, done{0};
    std::vector<std::atomic<long>> sphere_points(views.size()); // per sphere, for IBLCHECK_TRUTH_VERBOSE
    std::mutex progress_mutex;
    // Each row writes only its own pixels: the same bits for any thread count.
    parallel_for(H, threads, [&](int y) {
        long e = 0;
        for (int x = 0; x < W; ++x) {
            double rgb[3] = {0, 0, 0}, cov_total = 0, best = 0;
            for (size_t s = 0; s < views.size(); ++s) {
                if (!views[s].touches(x, y)) continue;
                double cov = 0;
                const long e0 = e;
                shade_pixel(views[s], env, tables[s].get(), acc, x, y, rgb, cov, e);
                sphere_points[s] += e - e0;
                cov_total += cov;
                if (cov > best) best = cov, out.sphere.at<int>(y, x) = int(s);
            }
            auto& px = out.image.at<cv::Vec3f>(y, x);
            for (int q = 0; q < 3; ++q) px[q] = float(rgb[q]);
            out.coverage.at<float>(y, x) = float(cov_total);
        }
        evals += e;
        const long d = done += row_work[size_t(y)];
        if (progress && total_work > 0) {
            std::lock_guard<std::mutex> lock(progress_mutex);
            progress(table_share + (1 - table_share) * double(d) / double(total_work));
        }
    });
    if (std::getenv("IBLCHECK_TRUTH_VERBOSE"))
        for (size_t s = 0; s < views.size(); ++s)
            fmt::print(stderr, "sphere {} ({}): footprint {} points\n", s, s < scene.labels.size() ? scene.labels[s] : "",
                       sphere_points[s].load());
    out.evaluations = table_evals;
    out.table_nodes = table_nodes;
    out.footprint_points = evals;
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

} // namespace iblcheck::truth

namespace iblcheck::truth {

namespace {
// A split-sum rung (split_sum.h): one level, the coarse one (half the time of the pair). It is not a
// truth: its provenance says so and carries no error bound of its own; its quadrature error is the
// coarse level's, which the truth's stated bound (coarse against fine) measures for the scene.
RenderResult split_sum_result(const TestSpec& spec, const TruthImage& img, const TruthAccuracy& acc, const std::string& split,
                              int threads, const std::string& lobes, const Environment& env,
                              std::chrono::steady_clock::time_point t0) {
    RenderResult res;
    const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    res.image = img.image;
    res.timings.push_back({"reference_cpu", total_s * 1000, false, false});
    res.texture_fetches_per_pixel = double(img.evaluations) / (double(img.image.cols) * img.image.rows);
    res.provenance = {{"method", "reference"},
                      {"integrator", "quadrature"},
                      {"split_sum", split},
                      {"deterministic", true},
                      {"scene", spec.scene},
                      {"options", spec.options.canonical()},
                      {"width", img.image.cols},
                      {"height", img.image.rows},
                      {"threads", threads},
                      {"lobes", lobes},
                      {"env", {{"spec", env.spec.empty() ? spec.env : env.spec}, {"content_hash", env.content_hash}}},
                      {"levels", {{"coarse", acc.json()}}},
                      {"evaluations", {{"coarse", img.evaluations}}},
                      {"time_s", total_s}};
    return res;
}
} // namespace

TruthRender render_truth(const TestSpec& spec, const Environment& env_in, const Progress& progress) {
    auto t0 = std::chrono::steady_clock::now();
    const Scene scene = build_scene(spec.scene, spec.options);
    const OptionMap& o = spec.options;
    const int W = spec.width > 0 ? spec.width : scene.width, H = spec.height > 0 ? spec.height : scene.height;
    const std::string lobes_s = option_choice(o, "lobes");
    const Lobes lobes = lobes_s == "diffuse" ? Lobes::diffuse : lobes_s == "specular" ? Lobes::specular : Lobes::all;
    int threads = option_int(o, "threads", "reference");
    if (threads < 0) throw UsageError("option 'threads': must be >= 0");
    threads = resolve_threads(threads);
    // Near-mirror lobes on smooth spheres: the outgoing radiance follows the environment's texel-scale
    // detail across the normals (the lobe is narrower than a texel), which the normal table would have to
    // resolve everywhere; measured on the 128x128 sphere at roughness 0.02 (α = 4e-4) under studio: the
    // coarse level alone did not finish in 12 min of CPU, and shading each footprint point directly did not
    // in 9. Bumped spheres keep the table (their pixels average a wide cone of normals).
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        const MaterialLobe L = material_lobe(scene.spheres[i].material, Lobes::all);
        if (L.glossy() && L.alpha < kNearMirrorAlpha && scene.spheres[i].bump_amplitude <= 0)
            throw UsageError(fmt::format("scene {}: sphere '{}' has roughness {} (α = {:.2g} < {}): a near-mirror lobe the "
                                         "quadrature truth cannot tabulate in reasonable time; render it with the Monte Carlo "
                                         "integrator (integrator=monte_carlo, spp=N)",
                                         spec.scene, i < scene.labels.size() ? scene.labels[i] : std::to_string(i),
                                         scene.spheres[i].material.roughness, L.alpha, kNearMirrorAlpha));
    }
    TruthAccuracy acc;
    acc.pixel_tolerance = option_double(o, "truth_tolerance", "reference");
    if (!(acc.pixel_tolerance > 0)) throw UsageError("option 'truth_tolerance': must be > 0");
    acc.env_tolerance = acc.pixel_tolerance / 4;
    Environment env = env_in;
    if (o.has("env_rotation")) env.rotation_deg = float(option_double(o, "env_rotation", "reference"));
    const EnvPyramid pyramid(env);
    TruthRender r;
    // Progress: the coarse level costs about half of the finer one (studio sweep: 46 s and 93 s of CPU).
    auto part = [&](double lo, double hi) -> Progress {
        if (!progress) return {};
        return [&progress, lo, hi](double f) { progress(lo + (hi - lo) * f); };
    };
    const std::string env_key = env.content_hash + "@" + std::to_string(env.rotation_deg);
    const std::string split_s = option_choice(o, "split_sum");
    if (split_s != "off") {
        r.coarse = render_truth_level(scene, W, H, pyramid, env_key, lobes, acc, threads, progress,
                                      split_s == "exact" ? SplitSum::exact : SplitSum::env_brdf_approx);
        r.result = split_sum_result(spec, r.coarse, acc, split_s, threads, lobes_s, env, t0);
        return r;
    }
    r.coarse = render_truth_level(scene, W, H, pyramid, env_key, lobes, acc, threads, part(0, 0.33));
    r.fine = render_truth_level(scene, W, H, pyramid, env_key, lobes, acc.finer(), threads, part(0.33, 1));
    r.bound = compare_levels(r.coarse, r.fine, scene);
    const double total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    RenderResult& res = r.result;
    res.image = r.fine.image;
    res.timings.push_back({"reference_cpu", total_s * 1000, false, false});
    long covered = cv::countNonZero(r.fine.coverage > 0);
    res.texture_fetches_per_pixel = double(r.fine.evaluations + r.coarse.evaluations) / (double(W) * H);
    res.provenance = {
        {"method", "reference"},
        {"integrator", "quadrature"},
        {"deterministic", true},
        {"scene", spec.scene},
        {"options", spec.options.canonical()},
        {"width", W},
        {"height", H},
        {"threads", threads},
        {"lobes", lobes_s},
        {"env",
         {{"spec", env.spec.empty() ? spec.env : env.spec},
          {"content_hash", env.content_hash},
          {"width", env.equirect.cols},
          {"height", env.equirect.rows},
          {"negatives_clamped", env.negatives_clamped},
          {"rotation_deg", env.rotation_deg}}},
        {"levels", {{"coarse", acc.json()}, {"fine", acc.finer().json()}}},
        {"evaluations", {{"coarse", r.coarse.evaluations}, {"fine", r.fine.evaluations}}},
        {"level_seconds", {{"coarse", r.coarse.seconds}, {"fine", r.fine.seconds}}},
        {"covered_pixels", covered},
        {"error_bound", r.bound.json()},
        {"time_s", total_s},
    };
    return r;
}

} // namespace iblcheck::truth
