// The normal table: its map, its agreement with direct quadrature, and its variation bound.
#include "renderers/reference/quadrature/normal_table.h"

#include <gtest/gtest.h>

#include <random>

using namespace iblcheck;
using namespace iblcheck::truth;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace normal_table_test {

namespace {
MaterialLobe lobe_of(double roughness, double metallic) {
    Material m;
    m.roughness = float(roughness), m.metallic = float(metallic), m.base_color = {0.9f, 0.6f, 0.5f};
    return material_lobe(m, Lobes::all);
}
} // namespace

TEST(NormalTable, EqualAreaMapRoundTrips) {
    EnvPyramid env(load_environment("constant:1"));
    const MaterialLobe L = lobe_of(1, 0);
    TableParams tp;
    tp.coarse = 0.5, tp.max_depth = 0;
    const V3 v = normalize(V3{0.2, 0.1, 1}), r = normalize(V3{1, 0, -0.2}),
             u{v.y * r.z - v.z * r.y, v.z * r.x - v.x * r.z, v.x * r.y - v.y * r.x};
    NormalTable t(env, L, v, r, u, tp, QuadratureParams{}, 1);
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> q(-1, 1);
    for (int k = 0; k < 200; ++k) {
        V3 n = normalize(V3{q(rng), q(rng), q(rng)});
        if (dot(n, v) < -0.4) continue;
        double X, Y;
        t.to_map(n, X, Y);
        const V3 m = t.from_map(X, Y);
        EXPECT_NEAR(dot(m, n), 1.0, 1e-12);
    }
}

// Lookups against direct quadrature at random normals (studio, a rough and a narrow lobe): within the
// table's tolerance where the lobe is smooth, and on average for the narrow one.
TEST(NormalTable, LookupsMatchDirectQuadrature) {
    Environment e = load_environment("studio");
    EnvPyramid env(e);
    QuadratureParams qp;
    qp.tolerance = 2e-4, qp.floor = 1e-3 * env.mean_radiance();
    for (auto [rough, metal, tol] : {std::tuple{0.7, 1.0, 2e-3}, {0.3, 0.0, 5e-3}}) {
        const MaterialLobe L = lobe_of(rough, metal);
        TableParams tp;
        tp.tolerance = 5e-3, tp.floor = qp.floor, tp.footprint = 0.02;
        NormalTable t(env, L, V3{0, 0, 1}, V3{1, 0, 0}, V3{0, 1, 0}, tp, qp, 2);
        std::mt19937 rng(3);
        std::uniform_real_distribution<double> q(-1, 1);
        double worst = 0, mean = 0;
        int n = 0;
        while (n < 60) {
            V3 nn = normalize(V3{q(rng), q(rng), std::fabs(q(rng)) + 0.3});
            double a[3], b[3] = {0, 0, 0};
            t.lookup(nn, a);
            shade(env, L, shading_point(nn, V3{0, 0, 1}, L), qp, b);
            for (int c = 0; c < 3; ++c) {
                const double rel = std::fabs(a[c] - b[c]) / (b[c] + qp.floor);
                worst = std::max(worst, rel), mean += rel / 3;
            }
            ++n;
        }
        mean /= n;
        EXPECT_LT(mean, tol) << "roughness " << rough;
        std::printf("table r=%.1f m=%.0f: %ld nodes, lookup vs quadrature: mean %.2e worst %.2e\n", rough, metal, t.nodes(), mean,
                    worst);
    }
}

// variation(n, radius) bounds the lookups over the cone.
TEST(NormalTable, VariationBoundsLookupsInTheCone) {
    Environment e = load_environment("sky_sun");
    EnvPyramid env(e);
    const MaterialLobe L = lobe_of(0.4, 1);
    TableParams tp;
    tp.tolerance = 2e-2, tp.floor = 1e-3 * env.mean_radiance();
    QuadratureParams qp;
    qp.tolerance = 2e-3, qp.floor = tp.floor;
    NormalTable t(env, L, V3{0, 0, 1}, V3{1, 0, 0}, V3{0, 1, 0}, tp, qp, 2);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> q(-1, 1), r01(0, 1);
    for (int k = 0; k < 100; ++k) {
        const V3 c = normalize(V3{q(rng), q(rng), std::fabs(q(rng)) + 0.2});
        const double radius = 0.01 + 0.2 * r01(rng);
        const double bound = t.variation(c, radius);
        double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
        for (int s = 0; s < 30; ++s) {
            V3 d = normalize(V3{q(rng), q(rng), q(rng)});
            const V3 n = normalize(c + std::tan(radius) * r01(rng) * normalize(d - dot(d, c) * c));
            double v[3];
            t.lookup(n, v);
            for (int ch = 0; ch < 3; ++ch) lo[ch] = std::min(lo[ch], v[ch]), hi[ch] = std::max(hi[ch], v[ch]);
        }
        const double d[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
        // Biquadratic leaves may overshoot their nodes slightly: 10 % slack.
        EXPECT_LE(rgb_size(d), 1.1 * bound + 1e-9) << k;
    }
}

// A cell's edge midpoint is shaded once for both cells on the edge (normal_table.cpp, SharedNodes): on a
// refined table many nodes are taken from a neighbour, and the table — its counts and every lookup — is
// the same whatever the number of building threads (two threads may race for a node; only one counts).
TEST(NormalTable, EdgeNodesAreShadedOnceWhateverTheThreads) {
    EnvPyramid env(load_environment("studio"));
    const MaterialLobe L = lobe_of(0.3, 1);
    QuadratureParams qp;
    qp.tolerance = 1e-3, qp.floor = 1e-3 * env.mean_radiance();
    TableParams tp;
    tp.tolerance = 2e-2, tp.floor = qp.floor, tp.footprint = 0.05, tp.max_depth = 4;
    const NormalTable one(env, L, V3{0, 0, 1}, V3{1, 0, 0}, V3{0, 1, 0}, tp, qp, 1);
    const NormalTable two(env, L, V3{0, 0, 1}, V3{1, 0, 0}, V3{0, 1, 0}, tp, qp, 2);
    // Each split cell shades 5 new points (4 edge midpoints and its centre) without sharing; with it, an
    // interior edge's midpoint is shaded by one of its two cells.
    EXPECT_GT(one.shared_nodes(), one.nodes() / 4) << one.nodes() << " nodes";
    EXPECT_EQ(one.nodes(), two.nodes());
    EXPECT_EQ(one.shared_nodes(), two.shared_nodes());
    EXPECT_EQ(one.evaluations(), two.evaluations());
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> q(-1, 1);
    for (int k = 0; k < 200; ++k) {
        const V3 n = normalize(V3{q(rng), q(rng), std::fabs(q(rng)) + 0.1});
        double a[3], b[3];
        one.lookup(n, a), two.lookup(n, b);
        for (int c = 0; c < 3; ++c) EXPECT_EQ(a[c], b[c]);
    }
}
} // namespace normal_table_test
