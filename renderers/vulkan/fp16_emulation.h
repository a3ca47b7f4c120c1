// fp16 arithmetic without shaderFloat16 (issue 15): a SPIR-V pass that widens every 16-bit float
// to 32 bits and rounds each fp16 operation's result back to fp16 (to nearest even, subnormals and
// overflow included), so precision=mediump means the same thing on every driver (fp16_emulation.cpp
// says why it is exact for + − × ÷ sqrt, where it is not, and why it does not use OpQuantizeToF16). Also the one rule that picks native or emulated
// fp16 (option fp16), used by the renderer and by `iblcheck doctor` alike.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace iblcheck::vk {

// How a precision=mediump shader computes its float16_t arithmetic.
enum class Fp16Path { native, emulated };

// Option fp16 (auto|native|emulated; default auto): auto is native when the device has
// shaderFloat16, else emulated. native on a device without shaderFloat16 throws EnvironmentError
// naming `device_name`; an unknown value throws UsageError.
Fp16Path choose_fp16_path(const std::string& requested, bool device_has_float16, const std::string& device_name);
const char* fp16_path_name(Fp16Path path);        // "native" | "emulated" (provenance)
std::string fp16_path_description(Fp16Path path); // one line for `iblcheck doctor`

// What emulate_fp16 did (tests check it; zero everywhere when the module had no 16-bit float).
struct Fp16EmulationStats {
    int rounded = 0;        // roundings to fp16 added (one per fp16 operation, OpFConvert f32→f16 included)
    int dots_expanded = 0;  // OpDot on f16 vectors rewritten as rounded products and sums
    int mixes_expanded = 0; // mix on f16 rewritten as rounded x·(1 − a) + y·a
    int constants = 0;      // 16-bit float constants converted to their 32-bit value
};

// Rewrites a SPIR-V module compiled with float16_t arithmetic so that it needs no Float16
// capability. Returns false and leaves `spirv` untouched when it declares no 16-bit float type.
// Throws ShaderCompileError for what cannot be widened without changing meaning (16-bit floats in
// buffers, push constants, images or interface variables, whose layout would change; bit casts of
// them; half matrices; 16-bit float controls), and if the result does not validate.
bool emulate_fp16(std::vector<uint32_t>& spirv, Fp16EmulationStats* stats = nullptr);

// spirv-val's verdict for Vulkan 1.2 (SPIR-V 1.5, what glslang targets here): "" when valid, else
// the validator's message.
std::string validate_spirv(const std::vector<uint32_t>& spirv);

} // namespace iblcheck::vk
