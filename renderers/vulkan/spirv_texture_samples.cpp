#include "spirv_texture_samples.h"

#include <map>
#include <set>

#include "kernel/errors.h"

namespace iblcheck::vk {

namespace {

// SPIR-V 1.5 opcodes (the unified specification, "3.49 Instructions").
constexpr uint32_t kOpName = 5, kOpFunction = 54, kOpFunctionEnd = 56, kOpFunctionCall = 57;
constexpr uint32_t kOpImageSampleFirst = 87, kOpImageDrefGather = 97; // OpImageSampleImplicitLod .. OpImageDrefGather

struct Function {
    double samples = 0;          // its own sample instructions
    std::vector<uint32_t> calls; // callee ids, one per call site
};

// A literal string operand (nul-terminated, packed little-endian in words).
std::string literal(const std::vector<uint32_t>& w, size_t first, size_t end) {
    std::string s;
    for (size_t i = first; i < end; ++i)
        for (int b = 0; b < 4; ++b) {
            const char c = char((w[i] >> (8 * b)) & 0xffu);
            if (c == '\0') return s;
            s += c;
        }
    return s;
}

double samples_of(uint32_t id, const std::map<uint32_t, Function>& fns, std::set<uint32_t>& stack) {
    auto it = fns.find(id);
    if (it == fns.end()) return 0;
    if (!stack.insert(id).second) throw Error("SPIR-V: a call cycle through function %" + std::to_string(id));
    double n = it->second.samples;
    for (uint32_t callee : it->second.calls) n += samples_of(callee, fns, stack);
    stack.erase(id);
    return n;
}

} // namespace

double image_samples_per_call(const std::vector<uint32_t>& spirv, const std::string& function_prefix) {
    std::map<uint32_t, Function> fns;
    std::map<uint32_t, std::string> names;
    uint32_t current = 0;
    for (size_t i = 5; i < spirv.size();) {
        const uint32_t op = spirv[i] & 0xffffu, count = spirv[i] >> 16;
        if (count == 0 || i + count > spirv.size()) throw Error("SPIR-V: malformed instruction at word " + std::to_string(i));
        if (op == kOpName && count >= 3) names[spirv[i + 1]] = literal(spirv, i + 2, i + count);
        if (op == kOpFunction && count >= 3) current = spirv[i + 2];
        if (op == kOpFunctionEnd) current = 0;
        if (current && op == kOpFunctionCall && count >= 4) fns[current].calls.push_back(spirv[i + 3]);
        if (current && op >= kOpImageSampleFirst && op <= kOpImageDrefGather) fns[current].samples += 1;
        if (current) fns[current]; // a function without samples or calls is still one
        i += count;
    }
    for (const auto& [id, name] : names)
        if (fns.count(id) && name.rfind(function_prefix, 0) == 0) {
            std::set<uint32_t> stack;
            return samples_of(id, fns, stack);
        }
    throw Error("SPIR-V: no function named " + function_prefix + "...");
}

} // namespace iblcheck::vk
