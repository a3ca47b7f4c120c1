// The pixel footprint: exact coverage of a sphere's silhouette (a disc under the orthographic camera)
// and the adaptive integral of the shading over pixel ∩ disc.
//
// Coverage: area and centroid of disc ∩ axis-aligned rectangle in closed form (inclusion–exclusion of
// the quadrant function P(a, b) = |disc ∩ [0,a]×[0,b]| = b·min(a, x*) + S(a) − S(min(a, x*)),
// S(x) = ∫₀ˣ √(r² − t²) dt, x* = √(r² − b²), and its first moments likewise).
// Integral: a quadtree over the pixel square. A square's one-point rule is |square ∩ disc| times the
// shading at the centroid of square ∩ disc (convex, so the centroid is on the sphere); its fine
// estimate the sum over its four children; adaptive_refine.h splits until the indicators sum to at most
// tolerance·(value + floor) per pixel. Squares shallower than min_depth are always split (features
// smaller than the first squares); where the caller gives a variation bound V (the range of the
// shading over the square, e.g. of a mirror's reflected radiance over the square's reflection cone),
// the indicator is at least `bound_weight`·|square ∩ disc|·V (V·area is the rule's worst case) for
// squares down to 2^-bound_depth px, so a small bright source inside a square cannot go unseen; below
// that the value indicator alone decides (the worst case is far too pessimistic to follow to the end:
// along a light's edge or at the rim, where a square's reflection cone stays wide, it would refine
// every square to the maximum depth).
#pragma once
#include <cstddef>
#include <functional>

namespace iblcheck::truth {

struct Disc {
    double cx = 0, cy = 0, r = 1; // pixel units (x right, y down)
};

// |disc ∩ [x0,x1]×[y0,y1]|; with mx/my, also the centroid of the intersection (undefined if empty).
double disc_rect_area(const Disc& d, double x0, double y0, double x1, double y1, double* mx = nullptr, double* my = nullptr);

struct FootprintParams {
    double tolerance = 1e-3; // relative, per pixel
    double floor = 0;        // absolute radiance added to the pixel's value in the tolerance
    int min_depth = 0;       // squares of side > 2^-min_depth px are always split
    int max_depth = 12;
    double bound_weight = 0.25; // weight of the variation bound in the indicator
    int bound_depth = 6;        // the bound applies to squares of side > 2^-bound_depth px
    size_t max_splits = 200000;
};

struct PixelIntegral {
    double rgb[3] = {0, 0, 0}; // mean over the pixel square (background contributes 0)
    double coverage = 0;       // |pixel ∩ disc|
    double error = 0;          // Σ indicators (rgb_size, mean over the pixel)
    long evaluations = 0;
    bool budget_hit = false;
};

// Shading at image position (x, y) (pixel units, inside the disc).
using PointShader = std::function<void(double x, double y, double rgb[3])>;
// Bound on the range of the shading over square [x0, x0+s]×[y0, y0+s] ∩ disc (rgb_size of hi − lo).
using VariationBound = std::function<double(double x0, double y0, double s)>;

PixelIntegral integrate_pixel(const Disc& d, int px, int py, const PointShader& g, const VariationBound* bound,
                              const FootprintParams& p);

} // namespace iblcheck::truth
