// A sphere under the orthographic camera (sphere_view.h).
#include "renderers/reference/quadrature/sphere_view.h"

#include <algorithm>
#include <cmath>

#include "kernel/errors.h"
#include "renderers/reference/quadrature/split_sum.h"

namespace iblcheck::truth {

SphereView::SphereView(const Scene& scene, int index, int W, int H, Lobes lobes) : sphere_(scene.spheres[size_t(index)]) {
    const Camera& c = scene.camera;
    // The camera basis of scene.h (camera_ray): forward, right = forward × world_up, up = right × forward.
    const V3 f = normalize(to_vec3d(c.target) - to_vec3d(c.eye)), wu = to_vec3d(c.world_up);
    right_ = normalize(V3{f.y * wu.z - f.z * wu.y, f.z * wu.x - f.x * wu.z, f.x * wu.y - f.y * wu.x});
    up_ = V3{right_.y * f.z - right_.z * f.y, right_.z * f.x - right_.x * f.z, right_.x * f.y - right_.y * f.x};
    back_ = -1.0 * f;
    const double hh = c.half_height, hw = hh * double(W) / H;
    wpp_ = 2 * hh / H;
    const V3 rel = to_vec3d(sphere_.center) - to_vec3d(c.eye);
    disc_.cx = (dot(rel, right_) / hw + 1) * W / 2;
    disc_.cy = (1 - dot(rel, up_) / hh) * H / 2;
    disc_.r = sphere_.radius / wpp_;
    lobe_ = material_lobe(sphere_.material, lobes);
}

V3 SphereView::offset(double x, double y) const {
    double dx = (x - disc_.cx) * wpp_, dy = -(y - disc_.cy) * wpp_;
    const double R = sphere_.radius, rho2 = dx * dx + dy * dy;
    if (rho2 > R * R) {
        const double s = R / std::sqrt(rho2);
        dx *= s, dy *= s;
    }
    const double dz = std::sqrt(std::max(0.0, R * R - dx * dx - dy * dy));
    return dx * right_ + dy * up_ + dz * back_;
}

V3 SphereView::normal(double x, double y) const { return normalize(offset(x, y)); }

V3 SphereView::bumped_normal(double x, double y) const {
    const V3 p = offset(x, y), n = normalize(p);
    if (sphere_.bump_amplitude <= 0) return n;
    const double pp[3] = {p.x, p.y, p.z}, nn[3] = {n.x, n.y, n.z};
    double out[3];
    bump_normal(sphere_, pp, nn, out);
    return {out[0], out[1], out[2]};
}

bool SphereView::touches(int px, int py) const {
    const double nx = std::clamp(disc_.cx, double(px), double(px + 1)) - disc_.cx;
    const double ny = std::clamp(disc_.cy, double(py), double(py + 1)) - disc_.cy;
    return nx * nx + ny * ny < disc_.r * disc_.r;
}

double SphereView::normal_cone(double x0, double y0, double s, V3& n) const {
    const double cx = x0 + s / 2, cy = y0 + s / 2;
    const V3 nc = normal(cx, cy);
    double min_cos = 1;
    for (int k = 0; k < 4; ++k) min_cos = std::min(min_cos, dot(nc, normal(x0 + (k & 1) * s, y0 + (k >> 1) * s)));
    n = bumped_normal(cx, cy);
    return std::min(kPi, 1.2 * std::acos(std::clamp(min_cos, -1.0, 1.0)) + tilt_bound(s));
}

double SphereView::tilt_bound(double s) const {
    const Sphere& sp = sphere_;
    return 1.2 * std::sqrt(2.0) * sp.bump_amplitude * sp.bump_frequency * sp.bump_frequency * wpp_ * s * 0.7072;
}

void SphereView::mirror(const EnvPyramid& env, double x, double y, double rgb[3]) const {
    const ShadingPoint s = shading_point(bumped_normal(x, y), back_, lobe_);
    double L[3];
    env.radiance(2 * s.nv * s.n - s.v, L);
    if (lobe_.split_sum == SplitSum::env_brdf_approx) { // split_sum.h: the fit's (A, B) at r = 0
        const Dfg g = env_brdf_approx(0, s.nv);
        for (int q = 0; q < 3; ++q) rgb[q] = (lobe_.f0[q] * g.a + g.b) * L[q];
        return;
    }
    // (split_sum=exact: the exact DFG at α = 0 is F(n·v) itself, so the split sum is exact here.)
    for (int q = 0; q < 3; ++q) rgb[q] = model::f_schlick(lobe_.f0[q], s.nv) * L[q];
}

double SphereView::mirror_variation(const EnvPyramid& env, double x0, double y0, double s) const {
    const double xs[5] = {x0 + s / 2, x0, x0 + s, x0, x0 + s}, ys[5] = {y0 + s / 2, y0, y0, y0 + s, y0 + s};
    V3 r[5];
    double nv_lo = 1, nv_hi = 0;
    for (int k = 0; k < 5; ++k) {
        const ShadingPoint sp = shading_point(bumped_normal(xs[k], ys[k]), back_, lobe_);
        r[k] = 2 * sp.nv * sp.n - sp.v;
        nv_lo = std::min(nv_lo, sp.nv), nv_hi = std::max(nv_hi, sp.nv);
    }
    // The square may hold the disc's centre (n·v = 1) or reach its rim (n·v → 0).
    if (disc_.cx >= x0 && disc_.cx <= x0 + s && disc_.cy >= y0 && disc_.cy <= y0 + s) nv_hi = 1;
    const double fx = std::max(std::fabs(x0 - disc_.cx), std::fabs(x0 + s - disc_.cx));
    const double fy = std::max(std::fabs(y0 - disc_.cy), std::fabs(y0 + s - disc_.cy));
    if (fx * fx + fy * fy >= disc_.r * disc_.r || sphere_.bump_amplitude > 0) nv_lo = kMinNdotV;
    if (sphere_.bump_amplitude > 0) nv_hi = 1;
    double min_cos = 1;
    for (int k = 1; k < 5; ++k) min_cos = std::min(min_cos, dot(r[0], r[k]));
    const double radius = std::min(kPi, std::acos(std::clamp(min_cos, -1.0, 1.0)) * 1.25 + 1e-6 + 4 * tilt_bound(s));
    double lo[3], hi[3];
    env.radiance_range(r[0], radius, lo, hi);
    double v[3];
    for (int q = 0; q < 3; ++q)
        v[q] = model::f_schlick(lobe_.f0[q], nv_lo) * hi[q] - model::f_schlick(lobe_.f0[q], nv_hi) * lo[q];
    return rgb_size(v);
}

std::vector<SphereView> sphere_views(const Scene& scene, int W, int H, Lobes lobes) {
    if (!scene.camera.orthographic)
        throw UsageError("scene " + scene.name +
                         ": the quadrature truth needs the orthographic camera (a constant view per sphere)");
    std::vector<SphereView> v;
    for (size_t i = 0; i < scene.spheres.size(); ++i) v.emplace_back(scene, int(i), W, H, lobes);
    for (size_t i = 0; i < v.size(); ++i)
        for (size_t j = i + 1; j < v.size(); ++j) {
            const double dx = v[i].disc().cx - v[j].disc().cx, dy = v[i].disc().cy - v[j].disc().cy;
            if (std::sqrt(dx * dx + dy * dy) < v[i].disc().r + v[j].disc().r)
                throw UsageError("scene " + scene.name + ": spheres " + std::to_string(i) + " and " + std::to_string(j) +
                                 " overlap on the image; the quadrature truth integrates each silhouette on its own");
        }
    return v;
}

} // namespace iblcheck::truth
