// L_o tabulated over normals, adaptively (normal_table.h).
#include "renderers/reference/quadrature/normal_table.h"

#include "renderers/reference/quadrature/split_sum.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <unordered_map>

#include "kernel/parallel_for.h"

namespace iblcheck::truth {

namespace {
constexpr double kBrightRatio = 4; // forced: the cone holds radiance > 4x what the cell's values see
} // namespace

// (Not in the anonymous namespace: NormalTable::Builder, declared in the header, holds a pointer to it.)
namespace table_detail {
// The shading at edge midpoints, shared by the two cells of equal size on either side of the edge (in
// the same coarse cell or across coarse cells, whichever thread builds them): each such node is shaded
// once instead of twice. Keyed by the node's position on the finest lattice and the cell size it was
// shaded for (a node's quadrature tolerance depends on that size), so a shared value is exactly the
// value either cell would have computed: the table is the same, bit for bit, with or without sharing.
// Sharded by key, one mutex per shard. Two threads may race to shade the same node; both compute the
// same value and only the first to store it counts its work, so the counts are deterministic too.
class SharedNodes {
  public:
    struct Value {
        std::array<float, 3> rgb;
    };
    bool find(uint64_t key, float out[3]) {
        Shard& sh = shard(key);
        std::lock_guard<std::mutex> lock(sh.m);
        const auto it = sh.map.find(key);
        if (it == sh.map.end()) return false;
        for (int q = 0; q < 3; ++q) out[q] = it->second.rgb[size_t(q)];
        return true;
    }
    // False if another thread stored the key first (the caller's work is then not counted).
    bool store(uint64_t key, const float v[3]) {
        Shard& sh = shard(key);
        std::lock_guard<std::mutex> lock(sh.m);
        return sh.map.emplace(key, Value{{v[0], v[1], v[2]}}).second;
    }

  private:
    struct Shard {
        std::mutex m;
        std::unordered_map<uint64_t, Value> map;
    };
    static constexpr size_t kShards = 64;
    Shard& shard(uint64_t key) { return shards_[(key * 0x9E3779B97F4A7C15ull) >> 58]; }
    std::array<Shard, kShards> shards_;
};
} // namespace table_detail
using table_detail::SharedNodes;

void NormalTable::to_map(V3 n, double& X, double& Y) const {
    const double c = std::max(-1 + 1e-12, dot(n, v_)), k = std::sqrt(2 / (1 + c));
    X = dot(n, r_) * k, Y = dot(n, u_) * k;
}

V3 NormalTable::from_map(double X, double Y) const {
    const double rho2 = X * X + Y * Y, s = std::sqrt(std::max(0.0, 1 - rho2 / 4));
    return (X * s) * r_ + (Y * s) * u_ + (1 - rho2 / 2) * v_;
}

// Builds one coarse cell's quadtree.
struct NormalTable::Builder {
    const NormalTable& t;
    const EnvPyramid& env;
    const MaterialLobe& lobe;
    const TableParams& tp;
    const QuadratureParams& qp;
    double floor_ = 0;
    SharedNodes* shared = nullptr;
    long nodes = 0, evals = 0, reused = 0;

    // An edge midpoint of a cell of size 2h: shaded once for both cells that share the edge.
    void shared_value(double X, double Y, float out[3], double h) {
        // Positions are dyadic multiples of the finest half-cell, coarse / 2^(max_depth + 1): exact integers.
        const double unit = std::ldexp(t.coarse_, -(tp.max_depth + 1));
        const auto ix = uint64_t(std::llround((X - t.x0_) / unit)), iy = uint64_t(std::llround((Y - t.x0_) / unit));
        const auto level = uint64_t(std::llround(std::log2(t.coarse_ / h)));
        const uint64_t key = (ix << 36) | (iy << 8) | level;
        if (shared->find(key, out)) {
            ++reused;
            return;
        }
        const long n0 = nodes, e0 = evals;
        value(X, Y, out, h);
        if (!shared->store(key, out)) nodes = n0, evals = e0, ++reused; // another thread shaded it first
    }

    // The shading at (X, Y), a node of cells of size s (0: the coarse grid).
    void value(double X, double Y, float out[3], double s = 0) {
        double rgb[3] = {0, 0, 0};
        ShadeStats st;
        const V3 n = t.from_map(X, Y);
        QuadratureParams q = qp;
        // Grazing normals cover little of the image (∝ n·v): their quadrature may be as much looser. Nodes
        // of cells smaller than a pixel's footprint enter a pixel (footprint/s)² at a time, their errors
        // (each from its own refinement) averaging as footprint/s: they may be as much looser too.
        q.tolerance /= std::clamp(dot(n, t.v_) + tp.weight_offset, 0.05, 1.0);
        if (s > 0 && s < tp.footprint) q.tolerance *= tp.footprint / s;
        if (lobe.split_sum != SplitSum::off)
            shade_split_sum(env, lobe, shading_point(n, t.v_, lobe), q, rgb, &st);
        else
            shade(env, lobe, shading_point(n, t.v_, lobe), q, rgb, &st);
        ++nodes, evals += st.evaluations;
        for (int q = 0; q < 3; ++q) out[q] = float(rgb[q]);
    }

    // A glossy lobe narrower than the cell, with radiance in the cell's reflection cone (its corners'
    // reflections, widened by 1.2), reflected at least by F0, far above what any of its nine values sees:
    // a compact bright source
    // (the sun) reflected inside the cell could then hide between them. (A source near the cone but
    // outside it reaches the cell through the lobe's tail, smoothly: the values see its gradient; a
    // large light's edge crosses the midlines, where the values differ and the interpolation test splits.)
    bool forced(double x0, double y0, double s, const float (&g)[9][3]) const {
        if (!lobe.glossy() || s <= tp.kappa * lobe.alpha) return false;
        auto refl = [&](double X, double Y) {
            const V3 n = t.from_map(X, Y);
            return 2 * dot(n, t.v_) * n - t.v_;
        };
        const V3 rc = refl(x0 + s / 2, y0 + s / 2);
        double min_cos = 1;
        for (int k = 0; k < 4; ++k) min_cos = std::min(min_cos, dot(rc, refl(x0 + (k & 1) * s, y0 + (k >> 1) * s)));
        const double radius = std::min(kPi, 1.2 * std::acos(std::clamp(min_cos, -1.0, 1.0)));
        double lo[3], hi[3];
        env.radiance_range(rc, radius, lo, hi);
        double seen = 0, hidden = 0;
        for (const auto& v : g) seen = std::max({seen, double(v[0]), double(v[1]), double(v[2])});
        for (int q = 0; q < 3; ++q) hidden = std::max(hidden, lobe.f0[q] * hi[q]); // at least F0 of it reflects
        return hidden > kBrightRatio * (seen + floor_);
    }

    // Fills tree[slot] for the cell (x0, y0, s) with corner values c00, c10, c01, c11.
    void build(std::vector<Cell>& tree, int slot, double x0, double y0, double s, int depth, const float* c00, const float* c10,
               const float* c01, const float* c11) {
        float g[9][3];
        for (int q = 0; q < 3; ++q) g[0][q] = c00[q], g[2][q] = c10[q], g[6][q] = c01[q], g[8][q] = c11[q];
        const double h = s / 2;
        shared_value(x0 + h, y0, g[1], h), shared_value(x0, y0 + h, g[3], h), value(x0 + h, y0 + h, g[4], h);
        shared_value(x0 + s, y0 + h, g[5], h), shared_value(x0 + h, y0 + s, g[7], h);
        // Cells wider than a pixel's footprint (in normal space) must interpolate well pointwise: the
        // largest difference between a test value and the bilinear prediction. Smaller cells only enter
        // pixels through their integral: the difference between the cell's trapezoid (corners) and
        // Simpson (3x3) integrals, the trapezoid's error (Simpson's, kept by the biquadratic leaf, is of
        // higher order), as a share of a pixel's value.
        double err = 0;
        if (s > tp.footprint) {
            const int mids[5][3] = {{1, 0, 2}, {3, 0, 6}, {5, 2, 8}, {7, 6, 8}, {4, -1, -1}};
            for (const auto& m : mids) {
                double d[3], a[3];
                for (int q = 0; q < 3; ++q) {
                    const double pred =
                        m[1] >= 0 ? 0.5 * (g[m[1]][q] + g[m[2]][q]) : 0.25 * (g[0][q] + g[2][q] + g[6][q] + g[8][q]);
                    d[q] = g[m[0]][q] - pred, a[q] = g[m[0]][q];
                }
                err = std::max(err, rgb_size(d) / (rgb_size(a) + floor_));
            }
        } else {
            const double w[9] = {1, 4, 1, 4, 16, 4, 1, 4, 1};
            double simpson[3] = {0, 0, 0}, trap[3], d[3];
            for (int q = 0; q < 3; ++q) {
                for (int k = 0; k < 9; ++k) simpson[q] += w[k] * g[k][q] / 36;
                trap[q] = 0.25 * (g[0][q] + g[2][q] + g[6][q] + g[8][q]);
                d[q] = simpson[q] - trap[q];
            }
            // A pixel holds (footprint/s)² such cells; their errors are largest along an edge, and add
            // along it: (footprint/s) of them, each weighing (s/footprint)² of the pixel.
            err = rgb_size(d) / (rgb_size(simpson) + floor_) * (s / tp.footprint);
        }
        // An error weighs by the image area its normals cover: ∝ n·v under the orthographic camera
        // (bump normals also appear where the smooth normal faces the viewer more: + weight_offset).
        double nv = -1;
        for (int k = 0; k < 9; ++k) nv = std::max(nv, dot(t.from_map(x0 + (k % 3) * h, y0 + (k / 3) * h), t.v_));
        err *= std::clamp(nv + tp.weight_offset, 0.02, 1.0);
        const bool split = depth < tp.max_depth && (err > tp.tolerance || forced(x0, y0, s, g));
        if (!split) {
            Cell& c = tree[size_t(slot)];
            for (int k = 0; k < 9; ++k)
                for (int q = 0; q < 3; ++q) c.v[k][q] = g[k][q];
            for (int q = 0; q < 3; ++q) {
                c.lo[q] = c.hi[q] = g[0][q];
                for (int k = 1; k < 9; ++k) c.lo[q] = std::min(c.lo[q], g[k][q]), c.hi[q] = std::max(c.hi[q], g[k][q]);
            }
            return;
        }
        const int first = int(tree.size());
        tree[size_t(slot)].child = first;
        tree.resize(tree.size() + 4);
        const int corner[4][4] = {{0, 1, 3, 4}, {1, 2, 4, 5}, {3, 4, 6, 7}, {4, 5, 7, 8}};
        for (int k = 0; k < 4; ++k)
            build(tree, first + k, x0 + (k & 1) * h, y0 + (k >> 1) * h, h, depth + 1, g[corner[k][0]], g[corner[k][1]],
                  g[corner[k][2]], g[corner[k][3]]);
        Cell& c = tree[size_t(slot)];
        for (int q = 0; q < 3; ++q) {
            c.lo[q] = tree[size_t(first)].lo[q], c.hi[q] = tree[size_t(first)].hi[q];
            for (int k = 1; k < 4; ++k)
                c.lo[q] = std::min(c.lo[q], tree[size_t(first + k)].lo[q]),
                c.hi[q] = std::max(c.hi[q], tree[size_t(first + k)].hi[q]);
        }
    }
};

NormalTable::NormalTable(const EnvPyramid& env, const MaterialLobe& lobe, V3 v, V3 right, V3 up, const TableParams& tp,
                         const QuadratureParams& qp, int threads, const std::function<void(double)>& progress)
    : v_(v), r_(right), u_(up), coarse_(tp.coarse) {
    const double max_rho = std::sqrt(2 * (1 - tp.min_nv)); // |(X, Y)| at n·v = min_nv
    n_ = int(std::ceil(2 * max_rho / coarse_)) + 1;
    x0_ = -0.5 * n_ * coarse_;
    trees_.resize(size_t(n_) * n_);
    // A coarse cell is needed when it reaches into |(X, Y)| ≤ max_rho.
    auto needed = [&](int i, int j) {
        const double a = x0_ + i * coarse_, b = x0_ + j * coarse_;
        const double nx = std::clamp(0.0, a, a + coarse_), ny = std::clamp(0.0, b, b + coarse_);
        return nx * nx + ny * ny <= max_rho * max_rho;
    };
    // Coarse grid nodes first (shared by the cells), then the cells; both in parallel, deterministic.
    std::vector<float> grid(size_t(n_ + 1) * (n_ + 1) * 3, 0.0f);
    std::atomic<int> done{0};
    std::mutex m;
    // Each grid row and each cell is written by its own index; the builders' counts are summed after the join.
    const std::vector<Builder> node_builders = parallel_for(
        n_ + 1, threads, [&] { return Builder{*this, env, lobe, tp, qp, tp.floor}; },
        [&](int j, Builder& b) {
            for (int i = 0; i <= n_; ++i) {
                bool use = false;
                for (int dj = -1; dj <= 0; ++dj)
                    for (int di = -1; di <= 0; ++di)
                        use |= i + di >= 0 && j + dj >= 0 && i + di < n_ && j + dj < n_ && needed(i + di, j + dj);
                if (use) b.value(x0_ + i * coarse_, x0_ + j * coarse_, &grid[(size_t(j) * (n_ + 1) + i) * 3]);
            }
        });
    SharedNodes shared;
    const std::vector<Builder> cell_builders = parallel_for(
        n_ * n_, threads, [&] { return Builder{*this, env, lobe, tp, qp, tp.floor, &shared}; },
        [&](int k, Builder& b) {
            const int i = k % n_, j = k / n_;
            if (needed(i, j)) {
                std::vector<Cell>& tree = trees_[size_t(k)];
                tree.resize(1);
                auto node = [&](int a, int c) { return &grid[(size_t(j + c) * (n_ + 1) + i + a) * 3]; };
                b.build(tree, 0, x0_ + i * coarse_, x0_ + j * coarse_, coarse_, 0, node(0, 0), node(1, 0), node(0, 1),
                        node(1, 1));
            }
            const int d = ++done;
            if (progress) {
                std::lock_guard<std::mutex> lock(m);
                progress(double(d) / (double(n_) * n_));
            }
        });
    for (const std::vector<Builder>* builders : {&node_builders, &cell_builders})
        for (const Builder& b : *builders) nodes_ += b.nodes, evals_ += b.evals, shared_ += b.reused;
}

long NormalTable::leaves() const {
    long n = 0;
    for (const auto& t : trees_)
        for (const Cell& c : t) n += c.child < 0;
    return n;
}

const NormalTable::Cell* NormalTable::leaf(double X, double Y, double& fx, double& fy) const {
    const double gx = (X - x0_) / coarse_, gy = (Y - x0_) / coarse_;
    const int i = std::clamp(int(std::floor(gx)), 0, n_ - 1), j = std::clamp(int(std::floor(gy)), 0, n_ - 1);
    const std::vector<Cell>& tree = trees_[size_t(j) * n_ + i];
    if (tree.empty()) return nullptr;
    fx = std::clamp(gx - i, 0.0, 1.0), fy = std::clamp(gy - j, 0.0, 1.0);
    const Cell* c = &tree[0];
    while (c->child >= 0) {
        const int a = fx >= 0.5, b = fy >= 0.5;
        fx = 2 * fx - a, fy = 2 * fy - b;
        c = &tree[size_t(c->child + a + 2 * b)];
    }
    return c;
}

void NormalTable::lookup(V3 n, double rgb[3]) const {
    double X, Y, fx, fy;
    to_map(n, X, Y);
    const Cell* c = leaf(X, Y, fx, fy);
    if (!c) {
        rgb[0] = rgb[1] = rgb[2] = 0;
        return;
    }
    // Biquadratic (Lagrange) on the leaf's 3x3 grid: nodes at t = 0, 1/2, 1.
    auto basis = [](double t, double w[3]) { w[0] = (2 * t - 1) * (t - 1), w[1] = 4 * t * (1 - t), w[2] = t * (2 * t - 1); };
    double wx[3], wy[3];
    basis(fx, wx), basis(fy, wy);
    rgb[0] = rgb[1] = rgb[2] = 0;
    for (int b = 0; b < 3; ++b)
        for (int a = 0; a < 3; ++a) {
            const double w = wx[a] * wy[b];
            for (int q = 0; q < 3; ++q) rgb[q] += w * c->v[3 * b + a][q];
        }
}

void NormalTable::range(size_t tree, int cell, double x0, double y0, double s, double bx0, double by0, double bx1, double by1,
                        double lo[3], double hi[3]) const {
    if (x0 > bx1 || x0 + s < bx0 || y0 > by1 || y0 + s < by0) return;
    const Cell& c = trees_[tree][size_t(cell)];
    const bool inside = x0 >= bx0 && x0 + s <= bx1 && y0 >= by0 && y0 + s <= by1;
    if (inside || c.child < 0) {
        for (int q = 0; q < 3; ++q) lo[q] = std::min(lo[q], double(c.lo[q])), hi[q] = std::max(hi[q], double(c.hi[q]));
        return;
    }
    const double h = s / 2;
    for (int k = 0; k < 4; ++k) range(tree, c.child + k, x0 + (k & 1) * h, y0 + (k >> 1) * h, h, bx0, by0, bx1, by1, lo, hi);
}

double NormalTable::variation(V3 n, double radius) const {
    double X, Y;
    to_map(n, X, Y);
    // The map stretches angles by at most 1/cos(θ/2) ≤ 2 across the radius (n·v ≥ −0.5): a cone of
    // `radius` lies inside a box of half-size 2·radius.
    const double e = 2 * radius + 1e-9;
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    const int i0 = std::clamp(int(std::floor((X - e - x0_) / coarse_)), 0, n_ - 1),
              i1 = std::clamp(int(std::floor((X + e - x0_) / coarse_)), 0, n_ - 1);
    const int j0 = std::clamp(int(std::floor((Y - e - x0_) / coarse_)), 0, n_ - 1),
              j1 = std::clamp(int(std::floor((Y + e - x0_) / coarse_)), 0, n_ - 1);
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            const size_t k = size_t(j) * n_ + i;
            if (trees_[k].empty()) continue;
            range(k, 0, x0_ + i * coarse_, x0_ + j * coarse_, coarse_, X - e, Y - e, X + e, Y + e, lo, hi);
        }
    if (lo[0] > hi[0]) return 0;
    const double d[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    return rgb_size(d);
}

} // namespace iblcheck::truth
