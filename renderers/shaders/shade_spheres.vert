#version 460
// Pass 5, shading=fragment, vertex stage: one instance per sphere, a 4-vertex strip covering its
// projection (impostor.glsl). Clip space: Vulkan's y points down as the pixel rows do.
#include "split_sum.glsl"
#include "impostor.glsl"
#if SHADING != SHADING_FRAGMENT
#error "shade_spheres.frag and .vert are the shading=fragment pass (renderers/option_table.cpp)"
#endif

// The camera and the sphere, flat: the fragment stage reads them from here, never from the scene
// buffer (impostor.glsl says why). Whole structs, so members added to SphereGpu travel too.
layout(location = 0) flat out CameraGpu camera_out;  // locations 0-3
layout(location = 4) flat out SphereGpu sphere_out;  // locations 4 on

void main() {
    vec2 corner = vec2(float(gl_VertexIndex & 1), float(gl_VertexIndex >> 1)) * 2.0 - 1.0;
    vec2 size = vec2(pc.width, pc.height);
    camera_out = scene_camera();
    sphere_out = scene.spheres[gl_InstanceIndex];
    vec2 px = impostor_corner(camera_out, sphere_out, corner, size);
    gl_Position = vec4(px / size * 2.0 - 1.0, 0.5, 1.0);
}
