// Environment pyramid with exact texel integrals (env_pyramid.h).
#include "renderers/reference/quadrature/env_pyramid.h"

#include <algorithm>
#include <cmath>

namespace iblcheck::truth {

namespace {
// Env-space direction of (φ, cos θ), φ = (u − 0.5)·2π (environment.h's convention).
V3 env_dir(double phi, double z) {
    z = std::clamp(z, -1.0, 1.0);
    const double s = std::sqrt(std::max(0.0, 1 - z * z));
    return {s * std::sin(phi), z, -s * std::cos(phi)};
}
double phi_of(double u) { return (u - 0.5) * 2 * kPi; }

// Per channel, the weight offsets (EnvCell::wa) that give the rule channel q's first moment: with weights
// 1/4 ± a on the pair (p0, p1) and 1/4 ± b on (p2, p3), the rule's mean moves by a(p0 − p1) + b(p2 − p3)
// from the luminance's; that shift is set to the tangent part of m_q − m_Y (least squares on c's tangent
// plane, one pair alone when the second has collapsed), then scaled down so that no weight is negative.
void set_channel_weights(EnvCell& cell, const V3 pts[4], V3 e1, V3 e2) {
    for (auto& w : cell.wa) w[0] = w[1] = 0;
    if (cell.np != 4) return;
    const V3 c{cell.c[0], cell.c[1], cell.c[2]}, mY = double(cell.mlen) * c;
    const V3 d1 = pts[0] - pts[1], d2 = pts[2] - pts[3];
    const double a11 = dot(d1, e1), a21 = dot(d1, e2), a12 = dot(d2, e1), a22 = dot(d2, e2);
    const double det = a11 * a22 - a12 * a21, n1 = a11 * a11 + a21 * a21;
    for (int q = 0; q < 3; ++q) {
        const V3 shift = V3{cell.m[q][0], cell.m[q][1], cell.m[q][2]} - mY;
        const double r1 = dot(shift, e1), r2 = dot(shift, e2);
        double a = 0, b = 0;
        if (std::fabs(det) > 1e-9 * (n1 + a12 * a12 + a22 * a22))
            a = (r1 * a22 - r2 * a12) / det, b = (a11 * r2 - a21 * r1) / det;
        else if (n1 > 0)
            a = (r1 * a11 + r2 * a21) / n1;
        const double big = std::max(std::fabs(a), std::fabs(b));
        if (big > 0.25) a *= 0.25 / big, b *= 0.25 / big;
        cell.wa[q][0] = float(a), cell.wa[q][1] = float(b);
    }
}

// The cell's rule points: c ± √2·l_k, l_k the columns of the Cholesky factor of its second moment
// projected on c's tangent plane (they match the luminance-weighted mean and second moment).
void set_sigma_points(EnvCell& cell) {
    const V3 c{cell.c[0], cell.c[1], cell.c[2]};
    const V3 e1 = std::fabs(c.x) < 0.9 ? normalize(V3{0, -c.z, c.y}) : normalize(V3{c.z, 0, -c.x}); // ⊥ c
    const V3 e2{c.y * e1.z - c.z * e1.y, c.z * e1.x - c.x * e1.z, c.x * e1.y - c.y * e1.x};
    const float* m = cell.cov;
    auto quad = [&](V3 p, V3 q) {
        return p.x * (m[0] * q.x + m[1] * q.y + m[2] * q.z) + p.y * (m[1] * q.x + m[3] * q.y + m[4] * q.z) +
               p.z * (m[2] * q.x + m[4] * q.y + m[5] * q.z);
    };
    const double a = quad(e1, e1), b = quad(e1, e2), d = quad(e2, e2);
    V3 pts[4] = {c, c, c, c};
    cell.np = 1;
    if (a + d > 1e-18) {
        const double l11 = std::sqrt(std::max(a, 1e-30)), l21 = b / l11, l22 = std::sqrt(std::max(0.0, d - l21 * l21));
        const double r2 = std::sqrt(2.0);
        const V3 u1 = (r2 * l11) * e1 + (r2 * l21) * e2, u2 = (r2 * l22) * e2;
        pts[0] = normalize(c + u1), pts[1] = normalize(c - u1), pts[2] = normalize(c + u2), pts[3] = normalize(c - u2);
        cell.np = 4;
    }
    for (int k = 0; k < 4; ++k) cell.sp[k][0] = float(pts[k].x), cell.sp[k][1] = float(pts[k].y), cell.sp[k][2] = float(pts[k].z);
    set_channel_weights(cell, pts, e1, e2);
}
} // namespace

EnvPyramid::EnvPyramid(const Environment& env) {
    const cv::Mat& m = env.equirect;
    W_ = m.cols, H_ = m.rows;
    const double a = double(env.rotation_deg) * kPi / 180;
    rc_ = std::cos(a), rs_ = std::sin(a);
    data_.resize(size_t(W_) * H_ * 3);
    for (int j = 0; j < H_; ++j) {
        const float* row = m.ptr<float>(j);
        std::copy(row, row + size_t(W_) * 3, data_.begin() + ptrdiff_t(size_t(j) * W_ * 3));
    }
    row_z_.resize(size_t(H_) + 1);
    texel_omega_.resize(size_t(H_));
    for (int j = 0; j <= H_; ++j) row_z_[size_t(j)] = std::cos(j * kPi / H_);
    for (int j = 0; j < H_; ++j) texel_omega_[size_t(j)] = 2 * kPi / W_ * (row_z_[size_t(j)] - row_z_[size_t(j) + 1]);
    row_s_.resize(size_t(H_) + 1), col_s_.resize(size_t(W_) + 1), col_c_.resize(size_t(W_) + 1);
    for (int j = 0; j <= H_; ++j) row_s_[size_t(j)] = std::sin(j * kPi / H_);
    for (int i = 0; i <= W_; ++i)
        col_s_[size_t(i)] = std::sin(phi_of(double(i) / W_)), col_c_[size_t(i)] = std::cos(phi_of(double(i) / W_));
    taylor_ = 2 * kPi / W_ < 0.15 && kPi / H_ < 0.15; // series error < 0.15⁶/720 ≈ 2e-8
    sub_cos_.assign(16, std::vector<double>(size_t(H_)));
    for (int l = 0; l < 16; ++l)
        for (int j = 0; j < H_; ++j) sub_cos_[size_t(l)][size_t(j)] = std::cos(subcell_radius(j, 1 << l, 0));
    w_.push_back(W_), h_.push_back(H_);
    while (w_.back() > 2 || h_.back() > 1) w_.push_back((w_.back() + 1) / 2), h_.push_back((h_.back() + 1) / 2);
    cells_.resize(w_.size());
    build_level0(m);
    for (int k = 1; k < levels(); ++k) build_level(k);
    // Start where cells are about 45 degrees: 8 cells around.
    top_ = 0;
    while (top_ + 1 < levels() && w_[size_t(top_) + 1] >= 8) ++top_;
    double sum = 0;
    for (const EnvCell& c : cells_[0]) {
        double v[3] = {c.L[0], c.L[1], c.L[2]};
        sum += rgb_size(v);
    }
    mean_ = sum / (4 * kPi);
}

// Level 0: the exact integral of the bilinear interpolant over each texel. In u the texel [i, i+1]
// reads centres i−1, i, i+1: ∫ = (2π/W)·(L[i−1]/8 + 3L[i]/4 + L[i+1]/8). In θ the texel's upper half
// interpolates rows j−1, j and its lower half rows j, j+1; the weights are ∫ t·sin θ dθ in closed form
// (∫ θ sin θ = sin θ − θ cos θ); rows outside [0, H) are the edge row (the filter clamps v).
void EnvPyramid::build_level0(const cv::Mat&) {
    const double D = kPi / H_;
    auto i0 = [](double a, double b) { return std::cos(a) - std::cos(b); };
    auto i1 = [](double a, double b) { return (std::sin(b) - b * std::cos(b)) - (std::sin(a) - a * std::cos(a)); };
    std::vector<EnvCell>& out = cells_[0];
    out.resize(size_t(W_) * H_);
    auto at = [&](int i, int j) { return &data_[(size_t(std::clamp(j, 0, H_ - 1)) * W_ + size_t((i % W_ + W_) % W_)) * 3]; };
    for (int j = 0; j < H_; ++j) {
        const double tj = j * D, cj = tj + D / 2, tj1 = tj + D;
        const double up_t = (i1(tj, cj) - (tj - D / 2) * i0(tj, cj)) / D; // ∫ weight of row j over the upper half
        const double lo_t = (i1(cj, tj1) - cj * i0(cj, tj1)) / D;         // ∫ weight of row j+1 over the lower half
        const double wv[3] = {i0(tj, cj) - up_t, up_t + i0(cj, tj1) - lo_t, lo_t};
        const double zt = row_z_[size_t(j)], zb = row_z_[size_t(j) + 1];
        for (int i = 0; i < W_; ++i) {
            EnvCell& c = out[size_t(j) * W_ + i];
            for (int ch = 0; ch < 3; ++ch) {
                double s = 0, lo = 1e300, hi = -1e300;
                for (int dj = -1; dj <= 1; ++dj) {
                    const float *l = at(i - 1, j + dj), *m = at(i, j + dj), *r = at(i + 1, j + dj);
                    s += wv[dj + 1] * (0.125 * l[ch] + 0.75 * m[ch] + 0.125 * r[ch]);
                    lo = std::min({lo, double(l[ch]), double(m[ch]), double(r[ch])});
                    hi = std::max({hi, double(l[ch]), double(m[ch]), double(r[ch])});
                }
                c.L[ch] = float(s * 2 * kPi / W_);
                c.lo[ch] = float(lo), c.hi[ch] = float(hi);
            }
            const V3 g = to_world(env_dir(phi_of((i + 0.5) / W_), 0.5 * (zt + zb)));
            c.g[0] = float(g.x), c.g[1] = float(g.y), c.g[2] = float(g.z);
            set_texel_moments(c, i, j);
            set_sigma_points(c);
            double min_cos = 1;
            for (double fu : {0.0, 1.0})
                for (double z : {zt, zb}) min_cos = std::min(min_cos, dot(g, to_world(env_dir(phi_of((i + fu) / W_), z))));
            c.cos_radius = float(std::cos(std::min(kPi, std::acos(std::clamp(min_cos, -1.0, 1.0)) * 1.01 + 1e-7)));
            c.radius = float(std::acos(std::clamp(double(c.cos_radius), -1.0, 1.0)));
        }
    }
}

// Moments of texel (i, j)'s radiance distribution, luminance-weighted (R+G+B): the mean vector
// μ = ∫Y ω dΩ / ∫Y dΩ, c = μ/|μ|, and the second moment about c, S − μcᵀ − cμᵀ + ccᵀ (S = ∫Y ωωᵀ/∫Y).
// The bilinear radiance is smooth inside each quarter of the texel, so 2x2 Gauss–Legendre per quarter
// in (u, θ) integrates it to fourth order; a black texel gets its uniform (solid-angle) moments.
void EnvPyramid::set_texel_moments(EnvCell& c, int i, int j) const {
    const double g = 0.5 / std::sqrt(3.0), du = 0.5 / W_, dth = 0.5 * kPi / H_;
    double w_sum = 0, mu_e[3] = {0, 0, 0}, S[3][3] = {}, wu_sum = 0, mu_u[3] = {0, 0, 0}, Su[3][3] = {};
    double wq[3] = {0, 0, 0}, mq[3][3] = {}; // per channel: ∫L_q dΩ and ∫L_q ω dΩ
    for (int qa = 0; qa < 2; ++qa)
        for (int qb = 0; qb < 2; ++qb)
            for (int k = 0; k < 4; ++k) {
                const double u = (i + 0.5 * qa + 0.25) / W_ + ((k & 1) ? g : -g) * du;
                const double th = (j + 0.5 * qb + 0.25) * kPi / H_ + ((k >> 1) ? g : -g) * dth;
                const V3 d = env_dir(phi_of(u), std::cos(th));
                double L[3];
                bilinear_equirect(data_.data(), W_, H_, size_t(W_) * 3, u, th / kPi, L);
                const double area = std::sin(th), w = area * (L[0] + L[1] + L[2]);
                const double v[3] = {d.x, d.y, d.z};
                w_sum += w, wu_sum += area;
                for (int q = 0; q < 3; ++q) {
                    wq[q] += area * L[q];
                    for (int a = 0; a < 3; ++a) mq[q][a] += area * L[q] * v[a];
                }
                for (int a = 0; a < 3; ++a) {
                    mu_e[a] += w * v[a], mu_u[a] += area * v[a];
                    for (int b = 0; b < 3; ++b) S[a][b] += w * v[a] * v[b], Su[a][b] += area * v[a] * v[b];
                }
            }
    if (!(w_sum > 0)) { // black: the solid-angle moments
        w_sum = wu_sum;
        for (int a = 0; a < 3; ++a) {
            mu_e[a] = mu_u[a];
            for (int b = 0; b < 3; ++b) S[a][b] = Su[a][b];
        }
    }
    for (int a = 0; a < 3; ++a) {
        mu_e[a] /= w_sum;
        for (int b = 0; b < 3; ++b) S[a][b] /= w_sum;
    }
    // To world: the rotation about +Y, R = [[rc, 0, rs], [0, 1, 0], [−rs, 0, rc]]; S_w = R S Rᵀ.
    const double R[3][3] = {{rc_, 0, rs_}, {0, 1, 0}, {-rs_, 0, rc_}};
    double Sw[3][3] = {};
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
            for (int k = 0; k < 3; ++k)
                for (int l = 0; l < 3; ++l) Sw[a][b] += R[a][k] * S[k][l] * R[b][l];
    const V3 mu = to_world(V3{mu_e[0], mu_e[1], mu_e[2]});
    const double ml = std::sqrt(dot(mu, mu));
    const V3 cc = (1.0 / ml) * mu;
    const double m[3] = {mu.x, mu.y, mu.z}, cv[3] = {cc.x, cc.y, cc.z};
    const int idx[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (int e = 0; e < 6; ++e) {
        const int a = idx[e][0], b = idx[e][1];
        c.cov[e] = float(Sw[a][b] - m[a] * cv[b] - cv[a] * m[b] + cv[a] * cv[b]);
    }
    c.c[0] = float(cc.x), c.c[1] = float(cc.y), c.c[2] = float(cc.z);
    c.mlen = float(ml);
    for (int q = 0; q < 3; ++q) { // a black channel takes the luminance's mean
        const V3 m = wq[q] > 0 ? to_world(V3{mq[q][0] / wq[q], mq[q][1] / wq[q], mq[q][2] / wq[q]}) : mu;
        c.m[q][0] = float(m.x), c.m[q][1] = float(m.y), c.m[q][2] = float(m.z);
    }
}

// Second moment of a uniform distribution over a cell's tangent rectangle: (hx²/3)·ex exᵀ + (hy²/3)·ey eyᵀ.
void EnvPyramid::set_uniform_cov(EnvCell& c, const Rect& r) {
    const double ax = r.hx * r.hx / 3, ay = r.hy * r.hy / 3;
    const double x[3] = {r.ex.x, r.ex.y, r.ex.z}, y[3] = {r.ey.x, r.ey.y, r.ey.z};
    const int idx[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
    for (int e = 0; e < 6; ++e) c.cov[e] = float(ax * x[idx[e][0]] * x[idx[e][1]] + ay * y[idx[e][0]] * y[idx[e][1]]);
}

// Level k: sums of the 2x2 children; luminance-weighted (R+G+B) centroid of the children's centroids.
void EnvPyramid::build_level(int k) {
    const int w = w_[size_t(k)], h = h_[size_t(k)], cw = w_[size_t(k) - 1], ch = h_[size_t(k) - 1];
    std::vector<EnvCell>& out = cells_[size_t(k)];
    out.resize(size_t(w) * h);
    const int span = 1 << k;
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i) {
            EnvCell& c = out[size_t(j) * w + i];
            double L[3] = {0, 0, 0}, cen[3] = {0, 0, 0}, wsum = 0, lo[3] = {1e300, 1e300, 1e300},
                   hi[3] = {-1e300, -1e300, -1e300}, mq[3][3] = {};
            for (int b = 0; b < 2; ++b)
                for (int a = 0; a < 2; ++a) {
                    const int ii = 2 * i + a, jj = 2 * j + b;
                    if (ii >= cw || jj >= ch) continue;
                    const EnvCell& s = cells_[size_t(k) - 1][size_t(jj) * cw + ii];
                    const double wgt = double(s.L[0]) + s.L[1] + s.L[2];
                    wsum += wgt;
                    for (int q = 0; q < 3; ++q) {
                        L[q] += s.L[q];
                        for (int a = 0; a < 3; ++a) mq[q][a] += double(s.L[q]) * s.m[q][a];
                        cen[q] += wgt * s.mlen * s.c[q];
                        lo[q] = std::min(lo[q], double(s.lo[q]));
                        hi[q] = std::max(hi[q], double(s.hi[q]));
                    }
                }
            const int ti0 = i * span, ti1 = std::min(W_, (i + 1) * span), tj0 = j * span, tj1 = std::min(H_, (j + 1) * span);
            const double zt = row_z_[size_t(tj0)], zb = row_z_[size_t(tj1)];
            const double p0 = phi_of(double(ti0) / W_), p1 = phi_of(double(ti1) / W_);
            const V3 g = to_world(env_dir(0.5 * (p0 + p1), 0.5 * (zt + zb)));
            double min_cos = 1;
            for (double p : {p0, 0.5 * (p0 + p1), p1})
                for (double z : {zt, 0.5 * (zt + zb), zb}) min_cos = std::min(min_cos, dot(g, to_world(env_dir(p, z))));
            double rad = std::acos(std::clamp(min_cos, -1.0, 1.0)) * 1.01 + 1e-7;
            if (p1 - p0 > kPi / 2) rad = kPi; // very wide cells: no tight bound needed
            c.cos_radius = float(std::cos(std::min(kPi, rad)));
            c.radius = float(std::acos(std::clamp(double(c.cos_radius), -1.0, 1.0)));
            const double cl = std::sqrt(cen[0] * cen[0] + cen[1] * cen[1] + cen[2] * cen[2]);
            const V3 cc = cl > 0 ? V3{cen[0] / cl, cen[1] / cl, cen[2] / cl} : g;
            c.c[0] = float(cc.x), c.c[1] = float(cc.y), c.c[2] = float(cc.z);
            c.mlen = wsum > 0 ? float(std::min(1.0, cl / wsum)) : 1.0f;
            if (wsum > 0) {
                // Second moment about cc: Σ w_k (C_k + (μ_k − c_k)dᵀ + d(μ_k − c_k)ᵀ + d dᵀ) / Σ w_k, d = c_k − cc
                // (parallel-axis rule; C_k is about c_k, the child's mean vector is μ_k = mlen_k·c_k).
                double m[6] = {0, 0, 0, 0, 0, 0};
                for (int b = 0; b < 2; ++b)
                    for (int a = 0; a < 2; ++a) {
                        const int ii = 2 * i + a, jj = 2 * j + b;
                        if (ii >= cw || jj >= ch) continue;
                        const EnvCell& s = cells_[size_t(k) - 1][size_t(jj) * cw + ii];
                        const double wgt = (double(s.L[0]) + s.L[1] + s.L[2]) / wsum;
                        const double d[3] = {s.c[0] - cc.x, s.c[1] - cc.y, s.c[2] - cc.z};
                        const double o[3] = {(s.mlen - 1.0) * s.c[0], (s.mlen - 1.0) * s.c[1], (s.mlen - 1.0) * s.c[2]};
                        const int idx[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
                        for (int e = 0; e < 6; ++e) {
                            const int u = idx[e][0], v = idx[e][1];
                            m[e] += wgt * (s.cov[e] + o[u] * d[v] + d[u] * o[v] + d[u] * d[v]);
                        }
                    }
                for (int e = 0; e < 6; ++e) c.cov[e] = float(m[e]);
            } else {
                set_uniform_cov(c, rect(k, i, j));
                c.mlen = 1;
            }
            c.g[0] = float(g.x), c.g[1] = float(g.y), c.g[2] = float(g.z);
            for (int q = 0; q < 3; ++q) c.L[q] = float(L[q]), c.lo[q] = float(lo[q]), c.hi[q] = float(hi[q]);
            for (int q = 0; q < 3; ++q) // a black channel takes the luminance's mean vector
                for (int a = 0; a < 3; ++a) c.m[q][a] = L[q] > 0 ? float(mq[q][a] / L[q]) : c.mlen * c.c[a];
            set_sigma_points(c);
        }
}

void EnvPyramid::radiance(V3 dir, double rgb[3]) const {
    const V3 e = to_env(dir);
    const double u = 0.5 + std::atan2(e.x, -e.z) / (2 * kPi), v = std::acos(std::clamp(e.y, -1.0, 1.0)) / kPi;
    bilinear_equirect(data_.data(), W_, H_, size_t(W_) * 3, u, v, rgb);
}

// sin/cos of a small angle d by its series (|d| < 0.15: error < 2e-8), added to a tabulated edge angle.
namespace {
inline void small_sc(double d, double& s, double& c) {
    const double d2 = d * d;
    s = d * (1 - d2 / 6 * (1 - d2 / 20));
    c = 1 - d2 / 2 * (1 - d2 / 12 * (1 - d2 / 30));
}
} // namespace

void EnvPyramid::phi_sc(int i, double fu, double& sp, double& cp) const {
    if (!taylor_) {
        const double phi = phi_of((i + fu) / W_);
        sp = std::sin(phi), cp = std::cos(phi);
        return;
    }
    double s, c;
    small_sc(fu * 2 * kPi / W_, s, c);
    sp = col_s_[size_t(i)] * c + col_c_[size_t(i)] * s, cp = col_c_[size_t(i)] * c - col_s_[size_t(i)] * s;
}

void EnvPyramid::theta_sc(int j, double ft, double& st, double& ct) const {
    if (!taylor_) {
        const double th = (j + ft) * kPi / H_;
        st = std::sin(th), ct = std::cos(th);
        return;
    }
    double s, c;
    small_sc(ft * kPi / H_, s, c);
    st = row_s_[size_t(j)] * c + row_z_[size_t(j)] * s, ct = row_z_[size_t(j)] * c - row_s_[size_t(j)] * s;
}

V3 EnvPyramid::dir_in_texel(int i, double fu, int j, double ft, double* sin_theta) const {
    double sp, cp, st, ct;
    phi_sc(i, fu, sp, cp);
    theta_sc(j, ft, st, ct);
    if (sin_theta) *sin_theta = st;
    return to_world(V3{st * sp, ct, -st * cp});
}

void EnvPyramid::subcell(int i, int j, int n, int a, int b, V3& dir, double& omega, double rgb[3]) const {
    const double th0 = (j + double(b) / n) * kPi / H_, th1 = (j + double(b + 1) / n) * kPi / H_;
    const double z0 = std::cos(th0), z1 = std::cos(th1), zm = 0.5 * (z0 + z1);
    const double um = (i + (a + 0.5) / n) / W_;
    omega = 2 * kPi / (double(W_) * n) * (z0 - z1);
    dir = to_world(env_dir(phi_of(um), zm));
    bilinear_equirect(data_.data(), W_, H_, size_t(W_) * 3, um, std::acos(zm) / kPi, rgb);
}

void EnvPyramid::subcell_gauss(int i, int j, int n, int a, int b, V3 dir[4], double wL[4][3]) const {
    const double g = 0.5 / std::sqrt(3.0);
    const double w0 = 0.25 * (2 * kPi / (double(W_) * n)) * (kPi / (double(H_) * n));
    // The rule's nodes share two columns (fu) and two rows (ft): their sines and cosines once each.
    const double fu[2] = {(a + 0.5 - g) / n, (a + 0.5 + g) / n}, ft[2] = {(b + 0.5 - g) / n, (b + 0.5 + g) / n};
    double sp[2], cp[2], st[2], ct[2];
    for (int k = 0; k < 2; ++k) phi_sc(i, fu[k], sp[k], cp[k]), theta_sc(j, ft[k], st[k], ct[k]);
    if (n < 2) { // a whole texel: its nodes straddle the texel centre, the general filter
        for (int k = 0; k < 4; ++k) {
            const int kx = k & 1, ky = k >> 1;
            dir[k] = to_world(V3{st[ky] * sp[kx], ct[ky], -st[ky] * cp[kx]});
            double L[3];
            bilinear_equirect(data_.data(), W_, H_, size_t(W_) * 3, (i + fu[kx]) / W_, (j + ft[ky]) / H_, L);
            for (int q = 0; q < 3; ++q) wL[k][q] = w0 * st[ky] * L[q];
        }
        return;
    }
    // The bilinear filter (environment.h): texel centres at half-integers, so a sub-cell of a split texel
    // (n ≥ 2) lies in one quadrant, between the same four texels — the texel and its neighbours toward
    // that quadrant (u wraps, v clamps), with weights fx = fu ± 1/2, fy = ft ± 1/2.
    const bool left = 2 * a < n, up = 2 * b < n;
    const int x0 = left ? (i == 0 ? W_ - 1 : i - 1) : i, x1 = x0 + 1 == W_ ? 0 : x0 + 1;
    const int y0 = std::clamp(up ? j - 1 : j, 0, H_ - 1), y1 = std::clamp(up ? j : j + 1, 0, H_ - 1);
    const float *r0 = &data_[size_t(y0) * W_ * 3], *r1 = &data_[size_t(y1) * W_ * 3];
    const float *p00 = r0 + 3 * x0, *p10 = r0 + 3 * x1, *p01 = r1 + 3 * x0, *p11 = r1 + 3 * x1;
    for (int k = 0; k < 4; ++k) {
        const int kx = k & 1, ky = k >> 1;
        dir[k] = to_world(V3{st[ky] * sp[kx], ct[ky], -st[ky] * cp[kx]});
        const double fx = left ? fu[kx] + 0.5 : fu[kx] - 0.5, fy = up ? ft[ky] + 0.5 : ft[ky] - 0.5;
        for (int q = 0; q < 3; ++q) {
            const double L = (1 - fy) * ((1 - fx) * p00[q] + fx * p10[q]) + fy * ((1 - fx) * p01[q] + fx * p11[q]);
            wL[k][q] = w0 * st[ky] * L;
        }
    }
}

double EnvPyramid::subcell_radius(int j, int n, int /*b: the bound holds for every sub-row*/) const {
    const double dth = kPi / (double(H_) * n);
    const double smax = std::min(1.0, std::max(row_s_[size_t(j)], row_s_[size_t(j) + 1]) + dth);
    const double dph = 2 * kPi / (double(W_) * n) * smax;
    return 0.5 * std::sqrt(dth * dth + dph * dph) * 1.01;
}

EnvPyramid::Rect EnvPyramid::rect(int level, int i, int j, int a, int b) const {
    double u0, u1, t0, t1;
    if (level >= 0) {
        const int span = 1 << level;
        u0 = double(i * span) / W_, u1 = double(std::min(W_, (i + 1) * span)) / W_;
        t0 = double(j * span) * kPi / H_, t1 = double(std::min(H_, (j + 1) * span)) * kPi / H_;
    } else {
        const int n = 1 << -level;
        u0 = (i + double(a) / n) / W_, u1 = (i + double(a + 1) / n) / W_;
        t0 = (j + double(b) / n) * kPi / H_, t1 = (j + double(b + 1) / n) * kPi / H_;
    }
    const double zm = 0.5 * (std::cos(t0) + std::cos(t1)), phi = phi_of(0.5 * (u0 + u1));
    const double th = std::acos(zm);
    Rect r;
    r.g = to_world(env_dir(phi, zm));
    r.ex = to_world(V3{std::cos(phi), 0, std::sin(phi)});
    r.ey = to_world(V3{zm * std::sin(phi), -std::sin(th), -zm * std::cos(phi)});
    r.hx = std::sin(th) * (u1 - u0) * kPi;
    r.hy = 0.5 * (t1 - t0);
    return r;
}

// Texel bounds of the θ/φ box around a cone (φ possibly beyond [0, W): wrapped by the caller).
void EnvPyramid::cone_box(V3 dir, double radius, int& i0, int& i1, int& j0, int& j1) const {
    const V3 e = to_env(dir);
    const double th = std::acos(std::clamp(e.y, -1.0, 1.0)), ph = std::atan2(e.x, -e.z); // φ ∈ (−π, π]
    const double t0 = std::max(0.0, th - radius), t1 = std::min(kPi, th + radius);
    double dphi = kPi;
    if (th - radius > 0 && th + radius < kPi) {
        const double s = std::sin(radius) / std::sin(th);
        if (s < 1) dphi = std::asin(s) * 1.01 + 1e-9;
    }
    j0 = std::clamp(int(t0 / kPi * H_), 0, H_ - 1), j1 = std::clamp(int(t1 / kPi * H_), 0, H_ - 1);
    if (dphi >= kPi) {
        i0 = 0, i1 = W_ - 1;
        return;
    }
    i0 = int(std::floor((0.5 + (ph - dphi) / (2 * kPi)) * W_)), i1 = int(std::floor((0.5 + (ph + dphi) / (2 * kPi)) * W_));
}

void EnvPyramid::cone_cells(V3 dir, double radius, int level, std::vector<std::pair<int, int>>& out) const {
    out.clear();
    int i0, i1, j0, j1;
    cone_box(dir, radius, i0, i1, j0, j1);
    const int step = 1 << level;
    for (int j = j0 >> level; j <= (j1 >> level); ++j) {
        const size_t first = out.size();
        auto visit = [&](int t) {
            const int i = (((t % W_) + W_) % W_) >> level;
            for (size_t k = first; k < out.size(); ++k)
                if (out[k].first == i) return;
            out.emplace_back(i, j);
        };
        for (int t = i0; t < i1; t += step) visit(t);
        visit(i1);
        // A ragged last cell (W not a multiple of 2^k) can fall between two steps: visit it too.
        const int last = i0 + (((W_ - 1 - i0) % W_) + W_) % W_;
        if (last <= i1) visit(last);
    }
}

void EnvPyramid::radiance_range(V3 dir, double radius, double lo[3], double hi[3]) const {
    int i0, i1, j0, j1;
    cone_box(dir, radius, i0, i1, j0, j1);
    // The level whose cells the box spans at most 4 x 4 of.
    int k = 0;
    while (k + 1 < levels() && (((j1 >> k) - (j0 >> k)) > 3 || ((i1 - i0) >> k) > 3)) ++k;
    thread_local std::vector<std::pair<int, int>> cells;
    cone_cells(dir, radius, k, cells);
    for (int q = 0; q < 3; ++q) lo[q] = 1e300, hi[q] = -1e300;
    for (auto [i, j] : cells) {
        const EnvCell& c = cell(k, i, j);
        for (int q = 0; q < 3; ++q) lo[q] = std::min(lo[q], double(c.lo[q])), hi[q] = std::max(hi[q], double(c.hi[q]));
    }
}

} // namespace iblcheck::truth
