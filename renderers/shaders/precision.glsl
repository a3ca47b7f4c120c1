// Shading precision (option precision). PRECISION_MEDIUMP 1 computes the shading in explicit
// float16_t: lavapipe ignores the mediump qualifier (RelaxedPrecision) but computes float16_t as
// true fp16, so this is what a mobile GPU's half precision does to the result (max 65504,
// 11-bit mantissa). Without shaderFloat16 the host emulates it (option fp16,
// renderers/vulkan/fp16_emulation.h): every float16_t becomes a float rounded to fp16 after each
// operation.
#ifndef IBLCHECK_PRECISION_GLSL
#define IBLCHECK_PRECISION_GLSL
#ifndef PRECISION_MEDIUMP
#define PRECISION_MEDIUMP 0
#endif
#if PRECISION_MEDIUMP
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#define hfloat float16_t
#define hvec2 f16vec2
#define hvec3 f16vec3
#define hvec4 f16vec4
#else
#define hfloat float
#define hvec2 vec2
#define hvec3 vec3
#define hvec4 vec4
#endif
#endif
