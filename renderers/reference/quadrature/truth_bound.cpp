// The stated error bound: the difference between two refinement levels (truth_renderer.h).
#include <cmath>

#include "renderers/reference/quadrature/truth_renderer.h"

namespace iblcheck::truth {

namespace {
struct Acc {
    double sum = 0;
    long n = 0;
    double worst = 0, worst_rel = 0;
    int wx = -1, wy = -1;
    void add(const cv::Vec3f& a, const cv::Vec3f& b, int x, int y) {
        double t = 0, w = 0, wr = 0;
        for (int c = 0; c < 3; ++c) {
            const double d = double(a[c]) - b[c], m = 0.5 * (double(a[c]) + b[c]);
            const double term = d * d / (m * m + 1e-2);
            t += term;
            w = std::max(w, std::sqrt(term));
            if (m > 0.01) wr = std::max(wr, std::fabs(d) / m);
        }
        sum += t / 3, ++n;
        if (w > worst) worst = w, wx = x, wy = y;
        worst_rel = std::max(worst_rel, wr);
    }
};
} // namespace

TruthBound compare_levels(const TruthImage& coarse, const TruthImage& fine, const Scene& scene) {
    TruthBound b;
    Acc all;
    std::vector<Acc> per(scene.spheres.size());
    for (int y = 0; y < fine.image.rows; ++y)
        for (int x = 0; x < fine.image.cols; ++x) {
            if (fine.coverage.at<float>(y, x) <= 0) continue;
            const cv::Vec3f& a = coarse.image.at<cv::Vec3f>(y, x);
            const cv::Vec3f& f = fine.image.at<cv::Vec3f>(y, x);
            all.add(a, f, x, y);
            const int s = fine.sphere.at<int>(y, x);
            if (s >= 0) per[size_t(s)].add(a, f, x, y);
        }
    b.relative_rmse = all.n ? std::sqrt(all.sum / all.n) : 0.0;
    b.worst = all.worst, b.worst_relative = all.worst_rel, b.worst_x = all.wx, b.worst_y = all.wy;
    b.covered_pixels = all.n;
    for (size_t s = 0; s < per.size(); ++s) {
        SphereBound sb;
        sb.label = s < scene.labels.size() ? scene.labels[s] : "sphere " + std::to_string(s);
        sb.pixels = per[s].n;
        sb.relative_rmse = per[s].n ? std::sqrt(per[s].sum / per[s].n) : 0.0;
        sb.worst = per[s].worst, sb.worst_relative = per[s].worst_rel, sb.worst_x = per[s].wx, sb.worst_y = per[s].wy;
        b.spheres.push_back(sb);
    }
    return b;
}

nlohmann::json TruthBound::json() const {
    nlohmann::json s = nlohmann::json::array();
    for (const SphereBound& p : spheres)
        s.push_back({{"label", p.label},
                     {"pixels", p.pixels},
                     {"relative_rmse", p.relative_rmse},
                     {"worst_pixel", p.worst},
                     {"worst_pixel_relative", p.worst_relative},
                     {"worst_pixel_xy", {p.worst_x, p.worst_y}}});
    return {{"relative_rmse", relative_rmse},         {"worst_pixel", worst},
            {"worst_pixel_relative", worst_relative}, {"worst_pixel_xy", {worst_x, worst_y}},
            {"covered_pixels", covered_pixels},       {"per_sphere", s}};
}

} // namespace iblcheck::truth
