// One pixel of the Monte Carlo integrator (mc_pixel.h).
#include "renderers/reference/monte_carlo/mc_pixel.h"

#include <algorithm>
#include <cmath>

namespace iblcheck::reference {

void pixel_candidates(const Scene& scene, int W, int H, int x, int y, std::vector<int>& out) {
    out.clear();
    Vec3f oc, dc;
    camera_ray(scene, W, H, x + 0.5, y + 0.5, oc, dc);
    Vec3d o{oc.x, oc.y, oc.z}, d = normalize(Vec3d{dc.x, dc.y, dc.z});
    double slack = 0;
    for (int c = 0; c < 4; ++c) {
        Vec3f o2, d2;
        camera_ray(scene, W, H, x + (c & 1), y + (c >> 1), o2, d2);
        if (scene.camera.orthographic) {
            Vec3d dd = Vec3d{o2.x, o2.y, o2.z} - o;
            slack = std::max(slack, std::sqrt(dot(dd, dd)));
        } else {
            double cs = std::clamp(dot(d, normalize(Vec3d{d2.x, d2.y, d2.z})), -1.0, 1.0);
            slack = std::max(slack, std::acos(cs));
        }
    }
    slack = slack * 1.01 + 1e-5;
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        const Sphere& s = scene.spheres[i];
        Vec3d c = Vec3d{s.center.x, s.center.y, s.center.z} - o;
        double r = double(s.radius) * 1.0001 + 1e-6, along = dot(c, d), cc = dot(c, c);
        bool cand;
        if (scene.camera.orthographic) {
            double dist = std::sqrt(std::max(0.0, cc - along * along));
            cand = dist <= r + slack;
        } else {
            double D = std::sqrt(cc);
            if (D <= r)
                cand = true;
            else {
                double ang = std::acos(std::clamp(along / D, -1.0, 1.0));
                cand = ang <= std::asin(std::min(1.0, r / D)) + slack;
            }
        }
        if (cand) out.push_back(int(i));
    }
}

bool intersect_candidates(const Scene& scene, const std::vector<int>& cand, Vec3f origin, Vec3f dir, int& sphere, Vec3d& normal) {
    double best_t = INFINITY;
    sphere = -1;
    for (int i : cand) {
        double oc[3];
        double t = intersect_sphere(scene.spheres[i], origin, dir, oc);
        if (t >= best_t) continue;
        best_t = t;
        sphere = i;
        double px = oc[0] + t * dir.x, py = oc[1] + t * dir.y, pz = oc[2] + t * dir.z;
        normal = Vec3d{px, py, pz};
    }
    if (sphere < 0) return false;
    // Same rounding as intersect(): a float unit normal.
    double inv = 1.0 / std::sqrt(dot(normal, normal));
    normal = Vec3d{double(float(normal.x * inv)), double(float(normal.y * inv)), double(float(normal.z * inv))};
    normal = normalize(normal);
    return true;
}

PixelOut render_pixel(const PixelContext& ctx, int x, int y, int P, int M, uint32_t pat, uint32_t pix_seed, PixelScratch& scratch,
                      long& fetches) {
    PixelOut po;
    const std::vector<int>& cand = scratch.cand;
    const LightSeeds seeds{hash_u32(pix_seed ^ 0x68bc21ebu), hash_u32(pix_seed ^ 0x02e5be93u), hash_u32(pix_seed ^ 0x7b3f9a11u)};
    double acc[3] = {0, 0, 0}, s1 = 0, s2 = 0;
    int hits = 0;
    std::vector<EnvWindow>& wins = scratch.windows;
    if (wins.size() < cand.size()) wins.resize(cand.size());
    std::vector<char>& win_built = scratch.built;
    win_built.assign(cand.size(), 0);
    if (!cand.empty())
        for (int k = 0; k < P; ++k) {
            double sx, sy;
            sobol_owen_2d(uint32_t(k), pat, sx, sy);
            Vec3f o3, d3;
            camera_ray(ctx.scene, ctx.W, ctx.H, x + sx, y + sy, o3, d3);
            int sph;
            Vec3d nrm;
            if (!intersect_candidates(ctx.scene, cand, o3, d3, sph, nrm)) continue;
            ++hits;
            Vec3d v = normalize(Vec3d{-d3.x, -d3.y, -d3.z});
            // This sphere's window, built at its first hit in the pixel.
            size_t ci = size_t(std::find(cand.begin(), cand.end(), sph) - cand.begin());
            if (ctx.shader.window && !win_built[ci]) {
                build_window(ctx.scene, ctx.W, ctx.H, x, y, sph, ctx.mats[size_t(sph)], ctx.shader.dist, ctx.lobe_window,
                             wins[ci]);
                win_built[ci] = 1;
            }
            double pos[3] = {0, 0, 0};
            for (int m = 0; m < M; ++m) {
                double one[3] = {0, 0, 0};
                shade(ctx.shader, ctx.mats[sph], wins[ci], nrm, v, seeds, uint32_t(k) * uint32_t(M) + uint32_t(m), one, fetches);
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
}

} // namespace iblcheck::reference
