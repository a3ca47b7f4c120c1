// iblcheck_reference_tool: renders one reference image (a golden) and its metadata.
//   iblcheck_reference_tool --scene S --env E [--spp N] [--seed K] [--threads T] [--set key=value]...
//                           --out FILE.exr [--meta FILE.json] [--noise-floor [--tiles WxH]] [--command "..."]
//   iblcheck_reference_tool --truth --scene S --env E [--set key=value]... [--frames N] --out FILE.exr [--compare OLD.exr]
//   iblcheck_reference_tool --diff A.exr B.exr [--tiles WxH] [--scene S]
// --noise-floor renders a second image with seed K+1 and records the relative RMSE between the two
// (reference.h, measure_noise_floor); the golden written is the seed-K image. --tiles WxH also prints the
// noise floor per WxH tile (48x48 = one sphere of the roughness sweep), to see where the noise is.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "metrics/flip.h"
#include "metrics/image_io.h"
#include "renderers/reference/reference.h"
#include "renderers/reference/sphere_view.h"
#include "renderers/reference/truth_golden.h"

using namespace iblcheck;

// --truth: the quadrature truth (truth_golden.h): golden + sidecar; --compare OLD.exr prints the mean FLIP
// and relative RMSE between the new golden and OLD (the check against the committed golden).
static int run_truth(TestSpec spec, const std::string& out_path, const std::string& command, const std::string& compare_path) {
    truth::GoldenRequest req;
    req.spec = spec;
    req.out_exr = out_path;
    req.command = command;
    const truth::GoldenWritten g = truth::write_truth_golden(req);
    const auto& b = g.meta["error_bound"];
    std::printf("%s: %dx%d time=%.1fs bound: rel_rmse=%.5f%% mean_flip=%.5f worst_pixel=%.5f worst_rel=%.5f criterion=%s\n",
                out_path.c_str(), g.meta["width"].get<int>(), g.meta["height"].get<int>(), g.meta["time_s"].get<double>(),
                100 * b["relative_rmse"].get<double>(), g.mean_flip, b["worst_pixel"].get<double>(),
                b["worst_pixel_relative"].get<double>(), g.criterion_met ? "met" : "NOT met");
    for (const auto& s : b["per_sphere"])
        std::printf("  %-16s rel_rmse=%.5f%% flip=%.5f worst=%.5f worst_rel=%.5f\n", s["label"].get<std::string>().c_str(),
                    100 * s["relative_rmse"].get<double>(), s["mean_flip"].get<double>(), s["worst_pixel"].get<double>(),
                    s["worst_pixel_relative"].get<double>());
    if (!compare_path.empty()) {
        const cv::Mat a = read_image(out_path).pixels, o = read_image(compare_path).pixels;
        check_same_size(a, o, out_path, compare_path);
        cv::Mat cov(a.rows, a.cols, CV_32FC1, cv::Scalar(0)); // covered: the truth's background is exactly 0
        for (int y = 0; y < a.rows; ++y)
            for (int x = 0; x < a.cols; ++x) {
                const cv::Vec3f& p = a.at<cv::Vec3f>(y, x);
                if (p[0] > 0 || p[1] > 0 || p[2] > 0) cov.at<float>(y, x) = 1;
            }
        const FlipResult fr = compute_flip_hdr(o, a, FlipOptions{});
        std::printf("against %s: mean FLIP %.5f, relative RMSE %.4f%%\n", compare_path.c_str(), fr.mean,
                    100 * relative_rmse(a, o, cov));
    }
    return 0;
}

// --diff A.exr B.exr [--tiles WxH]: mean HDR-FLIP (A as the reference) and relative RMSE between two images
// over the pixels either covers, overall and per tile (48x48: one sphere of the roughness sweep), with the
// worst pixel's relative RMSE term; for checking a new golden against the committed one sphere by sphere.
static int run_diff(const std::string& a_path, const std::string& b_path, int tile_w, int tile_h, const TestSpec& spec) {
    const cv::Mat a = read_image(a_path).pixels, b = read_image(b_path).pixels;
    check_same_size(a, b, a_path, b_path);
    cv::Mat cov(a.rows, a.cols, CV_32FC1, cv::Scalar(0));
    for (int y = 0; y < a.rows; ++y)
        for (int x = 0; x < a.cols; ++x) {
            const cv::Vec3f &p = a.at<cv::Vec3f>(y, x), &q = b.at<cv::Vec3f>(y, x);
            if (p[0] > 0 || p[1] > 0 || p[2] > 0 || q[0] > 0 || q[1] > 0 || q[2] > 0) cov.at<float>(y, x) = 1;
        }
    const FlipResult fr = compute_flip_hdr(a, b, FlipOptions{});
    std::printf("%s vs %s: mean FLIP %.5f, relative RMSE %.4f%%\n", a_path.c_str(), b_path.c_str(), fr.mean,
                100 * relative_rmse(a, b, cov));
    if (!spec.scene.empty()) { // split by the exact coverage of the scene's silhouettes (truth/footprint.h)
        const Scene scene = build_scene(spec.scene, spec.options);
        cv::Mat full(a.rows, a.cols, CV_32FC1, cv::Scalar(0)), part(a.rows, a.cols, CV_32FC1, cv::Scalar(0));
        for (const truth::SphereView& sv : truth::sphere_views(scene, a.cols, a.rows, truth::Lobes::all))
            for (int y = 0; y < a.rows; ++y)
                for (int x = 0; x < a.cols; ++x) {
                    const double c = truth::disc_rect_area(sv.disc(), x, y, x + 1, y + 1);
                    if (c >= 1 - 1e-9)
                        full.at<float>(y, x) = 1;
                    else if (c > 0)
                        part.at<float>(y, x) = 1;
                }
        std::printf("  fully covered pixels (%d): mean FLIP %.5f, relative RMSE %.4f%%; silhouette pixels (%d): mean FLIP "
                    "%.5f, relative RMSE %.4f%%\n",
                    cv::countNonZero(full), cv::mean(fr.errmap, full > 0)[0], 100 * relative_rmse(a, b, full),
                    cv::countNonZero(part), cv::mean(fr.errmap, part > 0)[0], 100 * relative_rmse(a, b, part));
    }
    if (tile_w <= 0) return 0;
    std::printf("per %dx%d tile: mean FLIP over covered pixels / relative RMSE / worst pixel term (x,y)\n", tile_w, tile_h);
    for (int ty = 0; ty < a.rows; ty += tile_h) {
        for (int tx = 0; tx < a.cols; tx += tile_w) {
            const cv::Rect rc(tx, ty, std::min(tile_w, a.cols - tx), std::min(tile_h, a.rows - ty));
            double worst = 0;
            int wx = -1, wy = -1;
            for (int y = rc.y; y < rc.y + rc.height; ++y)
                for (int x = rc.x; x < rc.x + rc.width; ++x) {
                    if (cov.at<float>(y, x) <= 0) continue;
                    for (int c = 0; c < 3; ++c) {
                        const double p = a.at<cv::Vec3f>(y, x)[c], q = b.at<cv::Vec3f>(y, x)[c], m = 0.5 * (p + q);
                        const double t = std::fabs(p - q) / std::sqrt(m * m + 0.01);
                        if (t > worst) worst = t, wx = x, wy = y;
                    }
                }
            std::printf("  tile %3d,%3d: FLIP %.5f  rel %.4f%%  worst %.4f (%d,%d)\n", tx, ty,
                        cv::mean(fr.errmap(rc), cov(rc) > 0)[0], 100 * relative_rmse(a(rc), b(rc), cov(rc)), worst, wx, wy);
        }
    }
    return 0;
}

// --truth --frames N: the temporal truth (truth_sequence.h) as one golden (frames stacked vertically).
static int run_truth_sequence(const TestSpec& spec, int frames, const std::string& out_path, const std::string& command) {
    truth::SequenceRequest req;
    req.spec = spec;
    req.frames = frames;
    req.bound_frames = {0, frames / 2};
    req.out_exr = out_path;
    req.command = command;
    const nlohmann::json m = truth::write_truth_sequence_golden(req);
    const auto& b = m["error_bound"];
    std::printf("%s: %d frames of %dx%d, time=%.1fs bound (frames %d, %d vs finer): rel_rmse<=%.4f%% mean_flip<=%.5f "
                "ldr_flip<=%.5f\n",
                out_path.c_str(), frames, m["width"].get<int>(), m["height"].get<int>(), m["time_s"].get<double>(),
                req.bound_frames[0], req.bound_frames[1], 100 * b["relative_rmse_max"].get<double>(),
                b["mean_flip_max"].get<double>(), b["mean_flip_ldr_max"].get<double>());
    return 0;
}

int main(int argc, char** argv) {
    try {
        TestSpec spec;
        spec.method = "reference";
        std::string out_path, meta_path, command;
        bool noise = false, truth = false;
        std::string compare_path, diff_a, diff_b;
        int tile_w = 0, tile_h = 0, frames = 0;
        int spp = kReferenceDefaultSpp, seed = 0;
        for (int i = 1; i < argc; ++i) {
            std::string a = argv[i];
            auto next = [&]() -> std::string {
                if (i + 1 >= argc) throw UsageError(a + " needs a value");
                return argv[++i];
            };
            if (a == "--scene")
                spec.scene = next();
            else if (a == "--env")
                spec.env = next();
            else if (a == "--spp")
                spec.options.set("spp", next());
            else if (a == "--seed")
                spec.options.set("seed", next());
            else if (a == "--threads")
                spec.options.set("threads", next());
            else if (a == "--width")
                spec.width = std::stoi(next());
            else if (a == "--height")
                spec.height = std::stoi(next());
            else if (a == "--set")
                spec.options.set_from_string(next());
            else if (a == "--out")
                out_path = next();
            else if (a == "--meta")
                meta_path = next();
            else if (a == "--noise-floor")
                noise = true;
            else if (a == "--command")
                command = next();
            else if (a == "--truth")
                truth = true;
            else if (a == "--frames")
                frames = std::stoi(next());
            else if (a == "--compare")
                compare_path = next();
            else if (a == "--diff") {
                diff_a = next();
                diff_b = next();
            } else if (a == "--tiles") {
                std::string t = next();
                if (std::sscanf(t.c_str(), "%dx%d", &tile_w, &tile_h) != 2 || tile_w < 1 || tile_h < 1)
                    throw UsageError("--tiles: expected WxH, e.g. 48x48, got '" + t + "'");
            } else
                throw UsageError("unknown argument '" + a + "' (see the comment at the top of tool.cpp)");
        }
        if (!diff_a.empty()) return run_diff(diff_a, diff_b, tile_w, tile_h, spec);
        if (out_path.empty()) throw UsageError("--out FILE.exr is required");
        if (truth && frames > 0) return run_truth_sequence(spec, frames, out_path, command);
        if (truth) return run_truth(spec, out_path, command, compare_path);
        spp = spec.options.get_int("spp", spp);
        seed = spec.options.get_int("seed", seed);
        auto t0 = std::chrono::steady_clock::now();
        nlohmann::json meta;
        cv::Mat image;
        if (noise) {
            NoiseFloor nf = measure_noise_floor(spec, spp);
            image = nf.image_a;
            const FlipResult fr = compute_flip_hdr(nf.image_a, nf.image_b, FlipOptions{});
            meta["noise_floor"] = {{"relative_rmse", nf.relative_rmse},
                                   {"definition", "sqrt(mean((a-b)^2 / (m^2 + 0.01))), m = (a+b)/2, over covered "
                                                  "pixels and channels; a/b = renders with seeds a/b"},
                                   {"mean_value", nf.mean_value},
                                   {"covered_pixels", nf.covered_pixels},
                                   {"seeds", {nf.seed_a, nf.seed_b}},
                                   {"mean_flip", fr.mean},
                                   {"what_differs",
                                    "the lighting random numbers only: both renders integrate each pixel's "
                                    "footprint with the same sub-pixel pattern (pixel_pattern), see reference.h"}};
            // Issue 5's convergence criterion, stated with its verdict.
            const double flip = fr.mean;
            meta["noise_floor"]["criterion"] = {{"mean_flip_below", 0.002},
                                                {"relative_rmse_below", 0.005},
                                                {"mean_flip_met", flip < 0.002},
                                                {"relative_rmse_met", nf.relative_rmse < 0.005},
                                                {"met", flip < 0.002 && nf.relative_rmse < 0.005}};
            meta["seeds"] = {nf.seed_a, nf.seed_b};
            if (tile_w > 0) {
                std::printf("noise floor per %dx%d tile: mean FLIP / relative RMSE (tiles with covered pixels)\n", tile_w,
                            tile_h);
                for (int ty = 0; ty < nf.image_a.rows; ty += tile_h) {
                    for (int tx = 0; tx < nf.image_a.cols; tx += tile_w) {
                        cv::Rect rc(tx, ty, std::min(tile_w, nf.image_a.cols - tx), std::min(tile_h, nf.image_a.rows - ty));
                        double rel = relative_rmse(nf.image_a(rc), nf.image_b(rc), nf.coverage(rc));
                        std::printf(" %.4f/%.2f%%", cv::mean(fr.errmap(rc))[0], 100 * rel);
                    }
                    std::printf("\n");
                }
                cv::Mat full = nf.coverage >= 1.0f, part = (nf.coverage > 0.0f) & (nf.coverage < 1.0f);
                cv::Mat fullf, partf;
                full.convertTo(fullf, CV_32F, 1.0 / 255), part.convertTo(partf, CV_32F, 1.0 / 255);
                std::printf("fully covered pixels: %d, FLIP %.4f, relative RMSE %.2f%%; partially covered: %d, FLIP %.4f, "
                            "relative RMSE %.2f%%\n",
                            cv::countNonZero(full), cv::mean(fr.errmap, full)[0],
                            100 * relative_rmse(nf.image_a, nf.image_b, fullf), cv::countNonZero(part),
                            cv::mean(fr.errmap, part)[0], 100 * relative_rmse(nf.image_a, nf.image_b, partf));
            }
            meta["provenance"] = nf.provenance_a;
        } else {
            meta["seeds"] = {seed};
        }
        spec.options.set("spp", std::to_string(spp));
        spec.options.set("seed", std::to_string(seed));
        if (!noise) {
            RenderResult r = render_reference(spec);
            image = r.image;
            meta["provenance"] = r.provenance;
        }
        double time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        Environment env = load_environment(spec.env);
        char date[64];
        std::time_t now = std::time(nullptr);
        std::strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
        meta["scene"] = spec.scene;
        meta["options"] = spec.options.canonical();
        meta["width"] = image.cols;
        meta["height"] = image.rows;
        meta["env"] = {{"spec", spec.env}, {"content_hash", env.content_hash}, {"negatives_clamped", env.negatives_clamped}};
        meta["spp"] = spp;
        meta["time_s"] = time_s;
        meta["command"] = command;
        meta["date"] = date;
        meta["image"] = std::filesystem::path(out_path).filename().string(); // beside the sidecar: no machine path
        meta["env"]["spec"] = truth::portable_env_spec(spec.env);
        meta["channels"] = "R,G,B float32 linear";
        if (!meta_path.empty() && std::filesystem::path(meta_path) != std::filesystem::path(out_path).replace_extension(".json"))
            throw UsageError("--meta must be the image's path with .json (" +
                             std::filesystem::path(out_path).replace_extension(".json").string() + ")");
        truth::write_golden_files(out_path, image, meta);
        std::printf("%s: %dx%d spp=%d time=%.1fs%s\n", out_path.c_str(), image.cols, image.rows, spp, time_s,
                    noise ? (" noise_floor=" + std::to_string(meta["noise_floor"]["relative_rmse"].get<double>())).c_str() : "");
        return 0;
    } catch (const UsageError& e) {
        std::cerr << "iblcheck_reference_tool: " << e.what() << "\n";
        return kExitError;
    } catch (const Error& e) {
        std::cerr << "iblcheck_reference_tool: " << e.what() << "\n";
        return kExitError;
    }
}
