// One sphere as the orthographic camera sees it: its silhouette disc in pixel units, the normal and
// view at an image position, and what the footprint integral needs per sphere (the mirror's reflected
// radiance and its variation bound, the minimum footprint depth for a lobe).
#pragma once
#include <vector>

#include "renderers/reference/quadrature/env_pyramid.h"
#include "renderers/reference/quadrature/footprint.h"
#include "renderers/reference/quadrature/truth_math.h"
#include "renderers/scenes/scene.h"

namespace iblcheck::truth {

class SphereView {
  public:
    SphereView(const Scene& scene, int index, int W, int H, Lobes lobes);
    const Disc& disc() const { return disc_; }
    const Sphere& sphere() const { return sphere_; }
    const MaterialLobe& lobe() const { return lobe_; }
    void set_split_sum(SplitSum m) { lobe_.split_sum = m; } // split_sum.h's rungs
    V3 view() const { return back_; }
    V3 right() const { return right_; }
    V3 up() const { return up_; }
    double world_per_pixel() const { return wpp_; }
    // Smooth-sphere normal at image position (x, y) (pixel units); positions outside the disc are
    // taken on its rim.
    V3 normal(double x, double y) const;
    // The point on the sphere relative to its centre (world units), and the bumped normal there
    // (scene.h, bump_normal; the smooth normal when the sphere has no bumps).
    V3 offset(double x, double y) const;
    V3 bumped_normal(double x, double y) const;
    bool touches(int px, int py) const; // pixel ∩ disc ≠ ∅
    // A cone holding every (bumped) normal of square [x0, x0+s]² ∩ disc: its axis (returned in n, the
    // bumped normal at the centre) and radius: 1.2 × the smooth normal's spread to the corners, plus the
    // bump tilt's Lipschitz bound 1.2·√2·A·f² per world unit (∇h changes at most A·f² per unit in each
    // component) over the centre-to-corner distance.
    double normal_cone(double x0, double y0, double s, V3& n) const;
    // The mirror's delta lobe at (x, y): F(n·v)·L(reflect(v)), n the bumped normal.
    void mirror(const EnvPyramid& env, double x, double y, double rgb[3]) const;
    // Bound on the range (rgb_size of hi − lo) of mirror() over square [x0, x0+s]² ∩ disc: the
    // radiance range over the square's reflection cone (its corners' and centre's reflections, the
    // widest angle × 1.25, plus 4x the bump tilt bound) scaled by the range of F.
    double mirror_variation(const EnvPyramid& env, double x0, double y0, double s) const;

  private:
    double tilt_bound(double s) const; // the bump tilt's bound over a square of side s (0 without bumps)
    Sphere sphere_;
    MaterialLobe lobe_;
    Disc disc_;
    double wpp_ = 1; // world units per pixel
    V3 right_, up_, back_;
};

// Every sphere of the scene. Throws UsageError for a perspective camera or overlapping silhouettes
// (each disc's footprint is integrated on its own: no occlusion between spheres).
std::vector<SphereView> sphere_views(const Scene& scene, int W, int H, Lobes lobes);

} // namespace iblcheck::truth
