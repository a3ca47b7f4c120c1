// Screen-space sphere impostors for the fragment path (option shading=fragment): the vertex
// shader covers each sphere's projection with a quad; the fragment shader intersects the camera
// ray through a position on the quad with that one sphere, the analytic surface the compute path
// ray-traces (scene.glsl: the same camera_ray_of and the same intersection arithmetic as
// intersect_scene). The camera and the sphere arrive as parameters, not from the scene buffer:
// the fragment stage gets them as flat vertex outputs (shade_spheres.vert), which helper
// invocations see too (on lavapipe 22.3 a storage-buffer load in a helper invocation returns
// undefined data, and derivatives need the helpers' normals). Needs scene.glsl.
#ifndef IBLCHECK_IMPOSTOR_GLSL
#define IBLCHECK_IMPOSTOR_GLSL

// The pixel position (x right, y down, in pixels) of world point x: the inverse of camera_ray_of.
vec2 world_to_pixel(CameraGpu cam, vec3 x, vec2 size) {
    vec3 f = cam.forward_half_h.xyz, r = cam.right_tan_half.xyz, u = cam.up_pad.xyz;
    float aspect = size.x / size.y;
    vec3 q = x - cam.eye_ortho.xyz;
    vec2 ndc;
    if (cam.eye_ortho.w > 0.5) {
        float hh = cam.forward_half_h.w;
        ndc = vec2(dot(q, r) / (hh * aspect), dot(q, u) / hh);
    } else {
        float th = cam.right_tan_half.w, z = dot(q, f);
        ndc = vec2(dot(q, r) / (z * th * aspect), dot(q, u) / (z * th));
    }
    return vec2((ndc.x + 1.0) * 0.5 * size.x, (1.0 - ndc.y) * 0.5 * size.y);
}

// Corner `corner` (each component −1 or +1) of the quad that covers sphere s's projection: a
// square in the plane through the centre facing the eye, half-size R·d/√(d² − R²) so it covers
// the cone of rays tangent to the sphere (R for parallel rays), pushed out 1.5 pixels so that no
// sample inside the silhouette falls outside it. In pixels.
vec2 impostor_corner(CameraGpu cam, SphereGpu s, vec2 corner, vec2 size) {
    vec3 c = s.center_radius.xyz;
    float rad = s.center_radius.w;
    vec3 w;
    float half_size;
    if (cam.eye_ortho.w > 0.5) {
        w = cam.forward_half_h.xyz;
        half_size = rad;
    } else {
        vec3 to_c = c - cam.eye_ortho.xyz;
        float d = length(to_c);
        w = to_c / d;
        half_size = rad * d / sqrt(max(d * d - rad * rad, 1e-12));
    }
    vec3 a = normalize(cross(w, cam.up_pad.xyz));
    vec3 b = cross(a, w);
    vec2 centre_px = world_to_pixel(cam, c, size);
    vec2 p = world_to_pixel(cam, c + half_size * (corner.x * a + corner.y * b), size);
    return p + normalize(p - centre_px) * 1.5;
}

// The surface of sphere s under pixel position p: normal n (with the scene's normal detail),
// view v, distance t along the ray. A miss returns false; with `clamp_to_silhouette` it still
// fills n, v with the silhouette point nearest the ray (n ⟂ v), which is what a mesh's normal
// extrapolated past its edge approximates: helper pixels outside the sphere then give finite
// derivatives to the quads that straddle the silhouette.
bool impostor_surface(CameraGpu cam, SphereGpu s, vec2 p, vec2 size, bool clamp_to_silhouette, out vec3 n, out vec3 v,
                      out float t) {
    vec3 o, d;
    camera_ray_of(cam, p, size, o, d);
    vec3 c = s.center_radius.xyz;
    float rad = s.center_radius.w;
    vec3 oc = o - c;
    float b = dot(oc, d);
    float q = dot(oc, oc) - rad * rad;
    float disc = b * b - q;
    v = -d;
    bool hit = disc >= 0.0 && -b - sqrt(max(disc, 0.0)) > 0.0;
    vec3 rel;
    if (hit) {
        t = -b - sqrt(disc);
        rel = o + d * t - c;
    } else {
        t = -b;  // closest approach
        vec3 off = oc + d * t;
        rel = off * (rad / max(length(off), 1e-12));
        if (!clamp_to_silhouette) return false;
    }
    n = bump_normal(rel, normalize(rel), s.roughness_bump);
    return hit;
}

#endif
