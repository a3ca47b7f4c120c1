#include "sphere_errors.h"

using nlohmann::json;

namespace iblcheck {

json per_sphere_errors(const SphereCoverage& coverage, const cv::Mat& errmap) {
    const size_t n = coverage.spheres.size();
    if (n < 2) return json();
    std::vector<double> sum(n, 0.0);
    std::vector<long> count(n, 0);
    for (int y = 0; y < errmap.rows; ++y)
        for (int x = 0; x < errmap.cols; ++x) {
            int id = coverage.ids.at<int>(y, x);
            if (id < 0) continue;
            sum[size_t(id)] += errmap.at<float>(y, x);
            count[size_t(id)]++;
        }
    json out = json::array();
    for (size_t i = 0; i < n; ++i) {
        if (!count[i]) continue;
        const SphereCoverage::Sphere& s = coverage.spheres[i];
        out.push_back(
            {{"label", s.label}, {"roughness", s.roughness}, {"metallic", s.metallic}, {"flip_mean", sum[i] / double(count[i])}});
    }
    return out;
}

SphereLayout sphere_layout(const SphereCoverage& coverage) {
    SphereLayout out;
    if (coverage.spheres.size() > 254) return out; // does not fit the 8-bit map: no layout
    coverage.ids.convertTo(out.ids, CV_8U, 1.0, 1.0);
    for (const SphereCoverage::Sphere& s : coverage.spheres)
        out.spheres.push_back({{"label", s.label}, {"roughness", s.roughness}, {"metallic", s.metallic}});
    return out;
}

std::string sphere_at(const SphereCoverage& coverage, int x, int y) {
    int id = coverage.ids.at<int>(y, x);
    return id < 0 ? "" : coverage.spheres[size_t(id)].label;
}

} // namespace iblcheck
