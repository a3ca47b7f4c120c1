// The project's one 3-vector: Vec3f for the data of scenes, cameras and options (positions,
// directions, "r,g,b" colours), Vec3d for the CPU truth's arithmetic, which is done in double.
// Plain aggregates; the few operations the renderers share are below.
#pragma once
#include <cmath>

namespace iblcheck {

template <class T> struct Vec3 { T x = 0, y = 0, z = 0; };
using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

template <class T> Vec3<T> operator+(Vec3<T> a, Vec3<T> b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
template <class T> Vec3<T> operator-(Vec3<T> a, Vec3<T> b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
template <class T> Vec3<T> operator*(T s, Vec3<T> a) { return {s * a.x, s * a.y, s * a.z}; }
template <class T> T dot(Vec3<T> a, Vec3<T> b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <class T> Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// a·(1/|a|): one division, as the truth's integrators have always normalised (their goldens'
// last bits depend on it).
template <class T> Vec3<T> normalize(Vec3<T> a) { return (T(1) / std::sqrt(dot(a, a))) * a; }

inline Vec3d to_vec3d(Vec3f v) { return {v.x, v.y, v.z}; }

} // namespace iblcheck
