// The project's 3-vector of floats: positions, directions and colours of scenes, cameras and
// options ("r,g,b" values). Plain data; the reference integrator does its arithmetic in double.
#pragma once

namespace iblcheck {

struct Vec3f {
    float x = 0, y = 0, z = 0;
};

} // namespace iblcheck
