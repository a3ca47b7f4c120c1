// iblcheck_truth_convergence: the quadrature truth's error against time (CONVERGENCE.md's table).
//   iblcheck_truth_convergence --scene S --env E [--set key=value]... [--threads T] [--per-sphere]
//                              --level KEY=V,KEY=V... [--level ...]   (keys: pixel, env, table, kappa, floor, bound)
//                              [--finer N] [--save PREFIX] [--against FINEST.exr] [--only SUBSTRING]...
// Renders each --level (an accuracy; unset keys keep TruthAccuracy's defaults), then N (default 2) successive
// finer() levels of the last one; the finest is the solution every level is measured against: relative
// RMSE (reference.h's definition), mean HDR-FLIP, worst pixel term, and each level's CPU time (user + sys of
// the process while it rendered) and wall time. --save PREFIX writes PREFIX<k>.exr per level. --against
// measures every level against a stored finest solution instead (--finer defaults to 0 then). --only keeps
// the spheres whose label contains one of the given substrings (the others are left out of the scene).
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "image_io/image_io.h"
#include "kernel/errors.h"
#include "metrics/flip.h"
#include "renderers/option_table.h"
#include "renderers/reference/quadrature/lobe_quadrature.h"
#include "renderers/reference/quadrature/truth_renderer.h"

using namespace iblcheck;
using namespace iblcheck::truth;

namespace {
double cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

TruthAccuracy parse_level(const std::string& text) {
    TruthAccuracy a;
    std::stringstream ss(text);
    for (std::string kv; std::getline(ss, kv, ',');) {
        const auto eq = kv.find('=');
        if (eq == std::string::npos) throw UsageError("--level: expected key=value, got '" + kv + "'");
        const std::string k = kv.substr(0, eq);
        const double v = std::stod(kv.substr(eq + 1));
        if (k == "pixel")
            a.pixel_tolerance = v;
        else if (k == "env")
            a.env_tolerance = v;
        else if (k == "table")
            a.table_tolerance = v;
        else if (k == "kappa")
            a.kappa = v;
        else if (k == "floor")
            a.floor = v;
        else if (k == "bound")
            a.bound_depth = int(v);
        else
            throw UsageError("--level: unknown key '" + k + "' (pixel, env, table, kappa, floor, bound)");
    }
    return a;
}
std::string fmt_levels(const TruthAccuracy& a) {
    char b[96];
    std::snprintf(b, sizeof b, "%.2g %.2g %.2g %.2g", a.pixel_tolerance, a.env_tolerance, a.table_tolerance, a.kappa);
    return b;
}
} // namespace

// --nodes: the quadrature rule alone at shading points (a grid of normals facing the viewer), each
// --level's kappa/env against the globally adaptive rule at tolerance 1e-6, kappa 0.125.
int run_nodes(const std::string& env_spec, const std::vector<TruthAccuracy>& levels, double min_nv) {
    const EnvPyramid env(load_environment(env_spec));
    const V3 v{0, 0, 1};
    std::vector<double> rs = {0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0};
    if (const char* e = std::getenv("NODES_R")) rs = {std::atof(e)};
    for (double r : rs) {
        for (double metal : {1.0, 0.0}) {
            Material m;
            m.roughness = float(r), m.metallic = float(metal), m.base_color = {0.9f, 0.6f, 0.5f};
            const MaterialLobe L = material_lobe(m, Lobes::all);
            std::vector<V3> ns;
            for (int a = 0; a < 7; ++a)
                for (int b = 0; b < 7; ++b) {
                    const double x = (a - 3) / 3.3 + 0.013, y = (b - 3) / 3.3 + 0.007;
                    if (x * x + y * y < 0.97) ns.push_back(V3{x, y, std::sqrt(1 - x * x - y * y)});
                }
            std::vector<double> ref(ns.size());
            QuadratureParams rp;
            rp.tolerance = 1e-6, rp.kappa = 0.125, rp.max_splits = 2000000;
            for (size_t k = 0; k < ns.size(); ++k) {
                double rgb[3] = {0, 0, 0};
                shade(env, L, shading_point(ns[k], v, L), rp, rgb);
                ref[k] = rgb_size(rgb);
            }
            for (const TruthAccuracy& a : levels) {
                QuadratureParams p;
                p.tolerance = a.env_tolerance, p.kappa = a.kappa;
                p.floor = a.floor * env.mean_radiance();
                double worst = 0, ss = 0;
                ShadeStats st;
                const double c0 = cpu_seconds();
                for (size_t k = 0; k < ns.size(); ++k) {
                    double rgb[3] = {0, 0, 0};
                    shade(env, L, shading_point(ns[k], v, L), p, rgb, &st);
                    const double e = std::fabs(rgb_size(rgb) - ref[k]) / (ref[k] + p.floor);
                    worst = std::max(worst, e), ss += e * e;
                }
                const double us = 1e6 * (cpu_seconds() - c0) / double(ns.size());
                std::printf("r=%.2f %s %-8s env %.2g kappa %.2g: rms %.2e worst %.2e, %6.0f evals/pt, %7.1f us/pt\n", r,
                            metal > 0 ? "metal" : "diel ", "adaptive", a.env_tolerance, a.kappa,
                            std::sqrt(ss / double(ns.size())), worst, double(st.evaluations) / double(ns.size()), us);
            }
        }
    }
    return 0;
}

namespace {
// The command line (the comment at the top).
struct Args {
    std::string scene_name = "roughness_sweep", env_spec = "studio", save, against;
    OptionMap opts;
    std::vector<TruthAccuracy> levels;
    int threads = 2, finer = 2;
    bool per_sphere = false, nodes = false;
    double min_nv = 0.25;
    std::vector<std::string> only;
};

Args parse_args(int argc, char** argv) {
    Args r;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) throw UsageError(a + " needs a value");
            return argv[++i];
        };
        if (a == "--scene")
            r.scene_name = next();
        else if (a == "--env")
            r.env_spec = next();
        else if (a == "--set")
            r.opts.set_from_string(next());
        else if (a == "--threads")
            r.threads = std::stoi(next());
        else if (a == "--level")
            r.levels.push_back(parse_level(next()));
        else if (a == "--finer")
            r.finer = std::stoi(next());
        else if (a == "--per-sphere")
            r.per_sphere = true;
        else if (a == "--nodes")
            r.nodes = true;
        else if (a == "--min-nv")
            r.min_nv = std::stod(next());
        else if (a == "--only")
            r.only.push_back(next());
        else if (a == "--save")
            r.save = next();
        else if (a == "--against")
            r.against = next(), r.finer = 0;
        else
            throw UsageError("unknown argument '" + a + "' (see the comment at the top of truth_convergence.cpp)");
    }
    if (r.levels.empty()) r.levels.push_back(TruthAccuracy{});
    return r;
}

// The scene's spheres whose label contains one of `only` (all when empty; a trailing '$' asks for the
// whole label: --only 'metal r=0$').
Scene keep_spheres(const Scene& scene, const std::vector<std::string>& only) {
    if (only.empty()) return scene;
    Scene kept = scene;
    kept.spheres.clear(), kept.labels.clear();
    for (size_t i = 0; i < scene.spheres.size(); ++i)
        for (const std::string& o : only)
            if (o.back() == '$' ? scene.labels[i] == o.substr(0, o.size() - 1) : scene.labels[i].find(o) != std::string::npos) {
                kept.spheres.push_back(scene.spheres[i]), kept.labels.push_back(scene.labels[i]);
                break;
            }
    return kept;
}

// Renders every level (CPU seconds of each in `cpu`), saving PREFIX<k>.exr with --save; with --against,
// the stored solution is appended as the last level (its coverage and spheres from level 0).
std::vector<TruthImage> render_levels(const Args& args, const Scene& scene, std::vector<TruthAccuracy>& levels,
                                      std::vector<double>& cpu) {
    Environment env = load_environment(args.env_spec);
    if (args.opts.has("env_rotation")) env.rotation_deg = float(option_double(args.opts, "env_rotation", "reference"));
    const EnvPyramid pyramid(env);
    const std::string key = env.content_hash + "@" + std::to_string(env.rotation_deg);
    std::vector<TruthImage> img;
    for (size_t k = 0; k < levels.size(); ++k) {
        const double c0 = cpu_seconds();
        img.push_back(render_truth_level(scene, scene.width, scene.height, pyramid, key, Lobes::all, levels[k], args.threads));
        cpu.push_back(cpu_seconds() - c0);
        if (!args.save.empty()) write_exr(args.save + std::to_string(k) + ".exr", img.back().image);
        std::fprintf(stderr, "level %zu %s: cpu %.1f s, wall %.1f s\n", k, levels[k].json().dump().c_str(), cpu.back(),
                     img.back().seconds);
    }
    if (!args.against.empty()) {
        TruthImage ref = img.front();
        ref.image = read_image(args.against).pixels;
        check_same_size(ref.image, img.front().image, args.against, "the rendered levels");
        img.push_back(ref);
        cpu.push_back(0);
        levels.push_back(levels.back());
    }
    return img;
}

// The table: every level against the last (relative RMSE, FLIP, worst pixel, evaluations), per sphere
// with --per-sphere.
void print_table(const Args& args, const Scene& scene, const std::vector<TruthAccuracy>& levels,
                 const std::vector<TruthImage>& img, const std::vector<double>& cpu) {
    const TruthImage& best = img.back();
    std::printf("%s / %s, against the finest level (%s)\n", args.scene_name.c_str(), args.env_spec.c_str(),
                levels.back().json().dump().c_str());
    std::printf("%-3s %-44s %9s %9s %9s %9s %8s %8s\n", "lvl", "accuracy (pixel env table kappa)", "cpu s", "wall s", "rel RMSE",
                "FLIP", "worst", "evals/1e6");
    for (size_t k = 0; k + 1 < img.size(); ++k) {
        const TruthBound b = compare_levels(img[k], best, scene);
        const double flip = compute_flip_hdr(best.image, img[k].image, FlipOptions{}).mean;
        const TruthAccuracy& a = levels[k];
        std::printf("%-3zu %-44s %9.1f %9.1f %8.4f%% %9.5f %8.4f %8.1f\n", k, fmt_levels(a).c_str(), cpu[k], img[k].seconds,
                    100 * b.relative_rmse, flip, b.worst, 1e-6 * double(img[k].evaluations));
        if (args.per_sphere)
            for (const SphereBound& s : b.spheres)
                std::printf("      %-16s rel %.4f%% worst %.4f (%d,%d)\n", s.label.c_str(), 100 * s.relative_rmse, s.worst,
                            s.worst_x, s.worst_y);
    }
    std::printf("%-3zu %-44s %9.1f %9.1f (the reference)\n", img.size() - 1, fmt_levels(levels.back()).c_str(), cpu.back(),
                best.seconds);
}
} // namespace

int main(int argc, char** argv) {
    try {
        const Args args = parse_args(argc, argv);
        std::vector<TruthAccuracy> levels = args.levels;
        if (args.nodes) return run_nodes(args.env_spec, levels, args.min_nv);
        for (int k = 0; k < args.finer; ++k) levels.push_back(levels.back().finer());
        const Scene scene = keep_spheres(build_scene(args.scene_name, args.opts), args.only);
        std::vector<double> cpu;
        const std::vector<TruthImage> img = render_levels(args, scene, levels, cpu);
        print_table(args, scene, levels, img, cpu);
        return 0;
    } catch (const Error& e) {
        std::cerr << "iblcheck_truth_convergence: " << e.what() << "\n";
        return kExitError;
    }
}
