// The fp16 emulation pass. What it does to a module glslang compiled with float16_t arithmetic:
//   * OpTypeFloat 16 becomes OpTypeFloat 32; the vector, pointer and function types built on it
//     then duplicate existing 32-bit ones and are merged into them (SPIR-V allows one declaration
//     of each non-aggregate type);
//   * 16-bit float constants become the 32-bit float of the same value (exact: fp16 ⊂ fp32);
//   * inside function bodies, every instruction whose result was a 16-bit float scalar or vector
//     gets a fresh result id and is followed by a rounding of that fresh value to fp16 whose last
//     instruction takes the original id, so every use sees the rounded value without renaming
//     anything; OpFConvert f32→f16 becomes the rounding itself and f16→f32 an OpCopyObject; OpDot
//     and mix are expanded into their fp16 operations (products and sums; x·(1 − a) + y·a, as
//     GLSL defines mix), each rounded, because one rounding of an fp32 dot product or mix is not
//     fp16 arithmetic;
//   * the Float16 capability (and the AMD half-float extension, which only it needs) is removed.
// Instructions that only move or select fp16 values already rounded (loads, composites, shuffles,
// select, copy, negate, calls, abs/min/max/clamp/floor/…) are left alone: their result is one of
// their operands or an integer-valued fp16, so rounding again would be the identity. OpPhi,
// OpVariable and OpFunctionParameter are left alone too: they must stay grouped at the start of a
// block or function, and they carry values rounded where they were computed.
//
// The rounding is spelled out in integer and float operations (round_to_half below), not
// OpQuantizeToF16: on a CPU without F16C, lavapipe (Mesa 22.3, LLVM 15) aborts with "stack
// smashing detected" when it compiles a shader with OpQuantizeToF16, and packHalf2x16 dies with an
// illegal instruction (measured with GALLIUM_OVERRIDE_CPU_CAPS=sse4.1), and a CPU without F16C is
// exactly where lavapipe lacks shaderFloat16. The sequence rounds to nearest even with fp16's
// range: overflow to ±inf and subnormals (which OpQuantizeToF16 may flush to zero) included.
//
// Why this is fp16 arithmetic for + − × ÷ and sqrt. Let x, y be fp16 values (q = 11 significant
// bits) and ∘ one of + − × ÷ (or √x). The widened shader computes r = RN24(x ∘ y) in fp32 (p = 24
// bits), then the rounding gives RN11(r); native fp16 gives RN11(x ∘ y).
//   1. fp32's exponent range does not interfere: every nonzero |x ∘ y| lies in [2^-48, 2^40]
//      (2^-24·2^-24 ≤ |x·y| ≤ 65504², 2^-24/65504 ≤ |x/y| ≤ 65504/2^-24), inside fp32's normal
//      range [2^-126, 2^128), so r is a plain 24-bit rounding.
//   2. Rounding to nearest twice is innocuous when p ≥ 2q + 2 (Figueroa 1995, "When is double
//      rounding innocuous?", ACM SIGNUM Newsletter 30(3); for + − × ÷ and √). Here 24 ≥ 2·11 + 2,
//      so RN11(RN24(x ∘ y)) = RN11(x ∘ y) with an unbounded exponent, and with it the overflow
//      decision (IEEE 754-2008 §7.4 decides overflow on that unbounded rounding: |x ∘ y| ≥ 65520
//      → ±inf). Below 2^-14 fp16 rounds to multiples of 2^-24, i.e. to fewer than 11 bits, which
//      only widens the margin (p ≥ 2q' + 2 for every q' ≤ 11).
// lavapipe computes native float16_t the same way (LLVM promotes half to float around each
// operation), and tests/test_fp16_emulation.cpp finds emulated, native and the CPU's _Float16
// bit-identical on + − × ÷ sqrt over random operands, subnormal and overflowing results included.
// Where the emulation is not fp16 arithmetic:
//   * extended instructions other than mix (exp2, pow, inversesqrt, smoothstep, normalize, …) are
//     evaluated by the driver's fp32 code and rounded once, where a driver with fp16 ALUs runs its
//     own fp16 sequence or approximation (lavapipe's fp16 smoothstep is several rounded
//     operations; sqrt is exact either way, being correctly rounded);
//   * no FMA contraction across a rounding: a native compiler may fuse an fp16 a·b + c into one fma
//     (one rounding); here a rounding separates the multiply from the add, so it never fuses;
//   * OpDot's order is ((x0·y0 + x1·y1) + x2·y2) + …, and mix is x·(1 − a) + y·a: one of several
//     a driver may use (measured: lavapipe's native fp16 uses these, and fuses no fp16 fma).
//
// This file is the rewriting of function bodies (BodyRewriter) and the pass's recipe
// (emulate_fp16); fp16_module.{h,cpp} is its bookkeeping: parsing, the type table, the ids and
// declarations it adds, the widening of the types at the end.
#include "fp16_emulation.h"

#include <glslang/SPIRV/GLSL.std.450.h>
#include <spirv-tools/libspirv.hpp>

#include <bit>
#include <cstring>
#include <unordered_map>

#include "fp16_module.h"
#include "kernel/errors.h"

namespace iblcheck::vk {

Fp16Path choose_fp16_path(const std::string& requested, bool device_has_float16, const std::string& device_name) {
    if (requested == "auto") return device_has_float16 ? Fp16Path::native : Fp16Path::emulated;
    if (requested == "emulated") return Fp16Path::emulated;
    if (requested == "native") {
        if (!device_has_float16)
            throw EnvironmentError(device_name + ": fp16=native needs shaderFloat16, which this device does not have; "
                                                 "use fp16=auto or fp16=emulated");
        return Fp16Path::native;
    }
    throw UsageError("option 'fp16': unknown value '" + requested + "'; valid: auto, native, emulated");
}

const char* fp16_path_name(Fp16Path path) { return path == Fp16Path::native ? "native" : "emulated"; }

std::string fp16_path_description(Fp16Path path) {
    return path == Fp16Path::native ? "native float16_t"
                                    : "emulated (fp32 rounded to fp16 after every fp16 operation; no shaderFloat16)";
}

std::string validate_spirv(const std::vector<uint32_t>& spirv) {
    spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
    std::string messages;
    tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& pos, const char* msg) {
        messages += "word " + std::to_string(pos.index) + ": " + msg + "\n";
    });
    if (tools.Validate(spirv)) return "";
    return messages.empty() ? "invalid SPIR-V" : messages;
}

namespace fp16 {
namespace {

// Results that equal one of the operands (or an integer-valued fp16), hence are fp16 values already.
bool is_exact(const Inst& i) {
    switch (i.op()) {
    case spv::OpLoad:
    case spv::OpCompositeExtract:
    case spv::OpCompositeInsert:
    case spv::OpCompositeConstruct:
    case spv::OpVectorShuffle:
    case spv::OpVectorExtractDynamic:
    case spv::OpVectorInsertDynamic:
    case spv::OpCopyObject:
    case spv::OpCopyLogical:
    case spv::OpSelect:
    case spv::OpFNegate:
    case spv::OpUndef:
    case spv::OpFunctionCall:
    case spv::OpPhi:
    case spv::OpVariable:
    case spv::OpFunctionParameter: return true;
    case spv::OpExtInst:
        if (!i.glsl_ext) return false;
        switch (GLSLstd450(i.words[4])) {
        case GLSLstd450Round:
        case GLSLstd450RoundEven:
        case GLSLstd450Trunc:
        case GLSLstd450FAbs:
        case GLSLstd450FSign:
        case GLSLstd450Floor:
        case GLSLstd450Ceil:
        case GLSLstd450FMin:
        case GLSLstd450FMax:
        case GLSLstd450FClamp:
        case GLSLstd450Step:
        case GLSLstd450NMin:
        case GLSLstd450NMax:
        case GLSLstd450NClamp: return true;
        default: return false;
        }
    default: return false;
    }
}

// Emits every instruction of the module in order, the function bodies rewritten: each fp16
// operation's result rounded to fp16, OpFConvert turned into a rounding or a copy, OpDot and mix
// expanded; module-level 16-bit constants widened, the Float16 capability dropped.
class BodyRewriter {
  public:
    BodyRewriter(const TypeTable& t, Declarations& d, Fp16EmulationStats& st) : t_(t), d_(d), st_(st) {}
    // The module's instructions rewritten, the declarations the rounding added before the first function.
    std::vector<Inst> rewrite(std::vector<Inst>& insts);
    // Original result id → the fresh id of the unrounded value.
    const std::unordered_map<uint32_t, uint32_t>& renamed() const { return renamed_; }

  private:
    bool keep_module_level(Inst& i);
    void rewrite_in_function(Inst& i);
    void round_result(Inst i);
    void round_to_half(uint32_t x, uint32_t type, uint32_t result);
    uint32_t emit(spv::Op o, uint32_t type, const std::vector<uint32_t>& args, uint32_t id = 0);
    void expand_dot(const Inst& i);
    void expand_mix(const Inst& i);
    uint32_t rounded_op(spv::Op o, uint32_t type, uint32_t l, uint32_t r, uint32_t id);

    const TypeTable& t_;
    Declarations& d_;
    Fp16EmulationStats& st_;
    std::vector<Inst> out_;
    std::unordered_map<uint32_t, uint32_t> renamed_;
};

std::vector<Inst> BodyRewriter::rewrite(std::vector<Inst>& insts) {
    out_.reserve(insts.size() * 4);
    size_t first_function = 0;
    bool in_function = false;
    for (Inst& i : insts) {
        spv::Op op = i.op();
        if (op == spv::OpFunction && !in_function && !first_function) first_function = out_.size();
        if (op == spv::OpFunction) in_function = true;
        if (op == spv::OpFunctionEnd) in_function = false;
        if (in_function && op != spv::OpFunction)
            rewrite_in_function(i);
        else if (keep_module_level(i))
            out_.push_back(std::move(i));
    }
    std::vector<Inst>& globals = d_.globals();
    out_.insert(out_.begin() + std::ptrdiff_t(first_function), std::make_move_iterator(globals.begin()),
                std::make_move_iterator(globals.end()));
    return std::move(out_);
}

// Outside function bodies: 16-bit float constants take their 32-bit value; false for what goes
// (the Float16 capability, and the AMD half-float extension, which only it needs).
bool BodyRewriter::keep_module_level(Inst& i) {
    spv::Op op = i.op();
    if (op == spv::OpConstant && t_.half_values.count(i.type)) {
        i.words[3] = half_bits_to_float_bits(i.words[3] & 0xffff);
        ++st_.constants;
    }
    if (op == spv::OpCapability && i.words[1] == spv::CapabilityFloat16) return false;
    return !(op == spv::OpExtension &&
             std::strcmp(reinterpret_cast<const char*>(&i.words[1]), "SPV_AMD_gpu_shader_half_float") == 0);
}

void BodyRewriter::rewrite_in_function(Inst& i) {
    spv::Op op = i.op();
    if (op == spv::OpFConvert && t_.is_f32_value(i.type) && t_.halfish.count(t_.type_of(i.words[3]))) {
        i.words[0] = (i.words[0] & 0xffff0000u) | spv::OpCopyObject; // f16 → f32: the value is already an fp16
        out_.push_back(std::move(i));
    } else if (!t_.half_values.count(i.type) || is_exact(i)) {
        out_.push_back(std::move(i));
    } else if (op == spv::OpFConvert && t_.is_f32_value(t_.type_of(i.words[3]))) {
        round_to_half(i.words[3], i.type, i.result); // f32 → f16 is the rounding itself
    } else if (op == spv::OpDot) {
        expand_dot(i);
    } else if (op == spv::OpExtInst && i.glsl_ext && i.words[4] == GLSLstd450FMix) {
        expand_mix(i);
    } else {
        round_result(std::move(i));
    }
}

// The instruction computes into a fresh id; its rounding takes the original one, so every use
// sees the rounded value without renaming anything.
void BodyRewriter::round_result(Inst i) {
    const uint32_t type = i.type, result = i.result;
    uint32_t fresh = d_.fresh();
    i.words[2] = fresh;
    i.result = fresh;
    renamed_[result] = fresh;
    out_.push_back(std::move(i));
    round_to_half(fresh, type, result);
}

// `o` of `type` on `args` (all ids) into `id` (a fresh one when 0); returns the id.
uint32_t BodyRewriter::emit(spv::Op o, uint32_t type, const std::vector<uint32_t>& args, uint32_t id) {
    if (!id) id = d_.fresh();
    std::vector<uint32_t> words = {type, id};
    std::vector<uint16_t> slots = {1};
    for (uint32_t a : args) {
        words.push_back(a);
        slots.push_back(uint16_t(words.size()));
    }
    out_.push_back(make(o, words, slots, type, id));
    return id;
}

// Rounds the fp32 value `x` of the (ex-fp16) type `type` to the nearest fp16, ties to even,
// with fp16's subnormals and overflow to ±inf, into `result`:
//   a = |x| bits, s = sign bit
//   normal range (a ≥ 2^-14): keep 10 mantissa bits, rounding the 13 dropped ones to nearest
//     even: (a + 0xfff + bit 13 of a) & ~0x1fff (a carry into the exponent is the right
//     answer); above 65504 (0x477fe000) after rounding it overflowed: +inf;
//   subnormal range (a < 2^-14): fp16 holds multiples of 2^-24 there: roundEven(|x|·2^24)·2^-24
//     (both products exact: powers of two in fp32's normal range);
//   NaN stays NaN; the sign is put back.
// (Not OpQuantizeToF16, which lavapipe cannot run without F16C: see the top of this file.)
void BodyRewriter::round_to_half(uint32_t x, uint32_t type, uint32_t result) {
    uint32_t n = t_.components(type);
    uint32_t u32 = d_.type_decl(spv::OpTypeInt, {32, 0}, {});
    uint32_t boolean = d_.type_decl(spv::OpTypeBool, {}, {});
    uint32_t ut = n == 1 ? u32 : d_.type_decl(spv::OpTypeVector, {u32, n}, {2});
    uint32_t bt = n == 1 ? boolean : d_.type_decl(spv::OpTypeVector, {boolean, n}, {2});
    auto uc = [&](uint32_t v) { return d_.constant(ut, u32, n, v); };
    auto fc = [&](float f) { return d_.constant(type, t_.half, n, std::bit_cast<uint32_t>(f)); };
    auto op = [&](spv::Op o, uint32_t ty, const std::vector<uint32_t>& args, uint32_t id = 0) { return emit(o, ty, args, id); };
    uint32_t u = op(spv::OpBitcast, ut, {x});
    uint32_t a = op(spv::OpBitwiseAnd, ut, {u, uc(0x7fffffffu)});
    uint32_t sign = op(spv::OpBitwiseAnd, ut, {u, uc(0x80000000u)});
    uint32_t lsb = op(spv::OpBitwiseAnd, ut, {op(spv::OpShiftRightLogical, ut, {a, uc(13)}), uc(1)});
    uint32_t r = op(spv::OpIAdd, ut, {op(spv::OpIAdd, ut, {a, uc(0x0fffu)}), lsb});
    r = op(spv::OpBitwiseAnd, ut, {r, uc(0xffffe000u)});
    r = op(spv::OpSelect, ut, {op(spv::OpUGreaterThan, bt, {r, uc(0x477fe000u)}), uc(0x7f800000u), r});
    uint32_t scaled = op(spv::OpFMul, type, {op(spv::OpBitcast, type, {a}), fc(0x1p24f)});
    uint32_t k = d_.fresh();
    out_.push_back(make(spv::OpExtInst, {type, k, t_.glsl_set, GLSLstd450RoundEven, scaled}, {1, 3, 5}, type, k));
    uint32_t sub = op(spv::OpBitcast, ut, {op(spv::OpFMul, type, {k, fc(0x1p-24f)})});
    r = op(spv::OpSelect, ut, {op(spv::OpULessThan, bt, {a, uc(0x38800000u)}), sub, r});
    r = op(spv::OpSelect, ut, {op(spv::OpUGreaterThan, bt, {a, uc(0x7f800000u)}), a, r});
    op(spv::OpBitcast, type, {op(spv::OpBitwiseOr, ut, {r, sign})}, result);
    ++st_.rounded;
}

// OpDot as Σ a_k·b_k from left to right, each product and each partial sum rounded to fp16: one
// rounding of an fp32 dot product is not fp16 arithmetic.
void BodyRewriter::expand_dot(const Inst& i) {
    const uint32_t type = i.type, result = i.result;
    uint32_t a = i.words[3], b = i.words[4], n = t_.count_of(t_.type_of(a)), acc = 0;
    for (uint32_t k = 0; k < n; ++k) {
        uint32_t ak = d_.fresh(), bk = d_.fresh(), prod = d_.fresh(), rounded = d_.fresh();
        out_.push_back(make(spv::OpCompositeExtract, {type, ak, a, k}, {1, 3}, type, ak));
        out_.push_back(make(spv::OpCompositeExtract, {type, bk, b, k}, {1, 3}, type, bk));
        out_.push_back(make(spv::OpFMul, {type, prod, ak, bk}, {1, 3, 4}, type, prod));
        round_to_half(prod, type, rounded);
        if (k == 0) {
            acc = rounded;
            continue;
        }
        uint32_t sum = d_.fresh(), next = k + 1 == n ? result : d_.fresh();
        out_.push_back(make(spv::OpFAdd, {type, sum, acc, rounded}, {1, 3, 4}, type, sum));
        round_to_half(sum, type, next);
        acc = next;
    }
    ++st_.dots_expanded;
}

// `l o r` rounded to fp16 into `id` (a fresh one when 0); returns the id.
uint32_t BodyRewriter::rounded_op(spv::Op o, uint32_t type, uint32_t l, uint32_t r, uint32_t id) {
    uint32_t raw = d_.fresh();
    out_.push_back(make(o, {type, raw, l, r}, {1, 3, 4}, type, raw));
    round_to_half(raw, type, id ? id : (id = d_.fresh()));
    return id;
}

// mix(x, y, a) as GLSL defines it, x·(1 − a) + y·a, each operation rounded to fp16.
void BodyRewriter::expand_mix(const Inst& i) {
    const uint32_t type = i.type, result = i.result;
    uint32_t x = i.words[5], y = i.words[6], a = i.words[7];
    uint32_t one = d_.constant(type, t_.half, t_.components(type), std::bit_cast<uint32_t>(1.0f));
    uint32_t keep = rounded_op(spv::OpFMul, type, x, rounded_op(spv::OpFSub, type, one, a, 0), 0);
    rounded_op(spv::OpFAdd, type, keep, rounded_op(spv::OpFMul, type, y, a, 0), result);
    ++st_.mixes_expanded;
}

} // namespace
} // namespace fp16

bool emulate_fp16(std::vector<uint32_t>& spirv, Fp16EmulationStats* stats) {
    fp16::Module m = fp16::parse(spirv);
    const fp16::TypeTable types = fp16::scan_types(m);
    if (types.half_values.empty()) return false;
    if (!types.glsl_set) throw ShaderCompileError("fp16 emulation: the module imports no GLSL.std.450 (glslang always does)");
    fp16::reject_unwidenable_uses(m, types);

    Fp16EmulationStats st;
    fp16::Declarations decls(types, m.header[3]);
    fp16::BodyRewriter rewriter(types, decls, st);
    std::vector<fp16::Inst> out = rewriter.rewrite(m.insts);
    std::vector<uint32_t> words = fp16::assemble_widened(out, m.header, decls.bound(), types.halfish, rewriter.renamed());
    if (std::string why = validate_spirv(words); !why.empty())
        throw ShaderCompileError("fp16 emulation produced invalid SPIR-V (a bug of the pass): " + why);
    spirv = std::move(words);
    if (stats) *stats = st;
    return true;
}

} // namespace iblcheck::vk
