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
#include "fp16_emulation.h"

#include <glslang/SPIRV/GLSL.std.450.h>
#include <glslang/SPIRV/spirv.hpp>
#include <spirv-tools/libspirv.hpp>

#include <bit>
#include <cstring>
#include <map>
#include <set>
#include <unordered_map>

#include "harness/common/errors.h"

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

namespace {

struct Inst {
    std::vector<uint32_t> words;
    std::vector<uint16_t> id_slots; // word indices of id operands, the result type's included, the result id's not
    spv::Op op() const { return spv::Op(words[0] & 0xffff); }
    uint32_t result = 0, type = 0;
    bool glsl_ext = false; // OpExtInst of GLSL.std.450
};

Inst make(spv::Op op, std::vector<uint32_t> operands, std::vector<uint16_t> id_slots, uint32_t type, uint32_t result) {
    Inst i;
    i.words.push_back(uint32_t(operands.size() + 1) << 16 | uint32_t(op));
    i.words.insert(i.words.end(), operands.begin(), operands.end());
    i.id_slots = std::move(id_slots);
    i.type = type;
    i.result = result;
    return i;
}

struct Module {
    std::vector<uint32_t> header;
    std::vector<Inst> insts;
};

Module parse(const std::vector<uint32_t>& spirv) {
    Module m;
    spv_context ctx = spvContextCreate(SPV_ENV_UNIVERSAL_1_6);
    spv_diagnostic diag = nullptr;
    auto on_header = [](void* user, spv_endianness_t, uint32_t magic, uint32_t version, uint32_t generator, uint32_t bound,
                        uint32_t schema) -> spv_result_t {
        static_cast<Module*>(user)->header = {magic, version, generator, bound, schema};
        return SPV_SUCCESS;
    };
    auto on_inst = [](void* user, const spv_parsed_instruction_t* p) -> spv_result_t {
        Inst i;
        i.words.assign(p->words, p->words + p->num_words);
        i.result = p->result_id;
        i.type = p->type_id;
        i.glsl_ext = p->ext_inst_type == SPV_EXT_INST_TYPE_GLSL_STD_450;
        for (uint16_t k = 0; k < p->num_operands; ++k) {
            spv_operand_type_t t = p->operands[k].type;
            if (t == SPV_OPERAND_TYPE_ID || t == SPV_OPERAND_TYPE_TYPE_ID || t == SPV_OPERAND_TYPE_SCOPE_ID ||
                t == SPV_OPERAND_TYPE_MEMORY_SEMANTICS_ID)
                i.id_slots.push_back(p->operands[k].offset);
        }
        static_cast<Module*>(user)->insts.push_back(std::move(i));
        return SPV_SUCCESS;
    };
    spv_result_t r = spvBinaryParse(ctx, &m, spirv.data(), spirv.size(), on_header, on_inst, &diag);
    std::string why = diag && diag->error ? diag->error : "";
    spvDiagnosticDestroy(diag);
    spvContextDestroy(ctx);
    if (r != SPV_SUCCESS) throw ShaderCompileError("fp16 emulation: cannot parse the SPIR-V: " + why);
    return m;
}

// The fp32 bit pattern of an fp16 one (exact; subnormals become normal fp32 values).
uint32_t half_bits_to_float_bits(uint32_t h) {
    uint32_t sign = (h >> 15 & 1) << 31, exp = h >> 10 & 0x1f, mant = h & 0x3ff;
    if (exp == 0x1f) return sign | 0x7f800000u | mant << 13;
    if (exp != 0) return sign | (exp + 112) << 23 | mant << 13;
    if (mant == 0) return sign;
    int e = 113; // value = mant · 2^-24: normalise the mantissa
    while (!(mant & 0x400)) {
        mant <<= 1;
        --e;
    }
    return sign | uint32_t(e) << 23 | (mant & 0x3ff) << 13;
}

bool is_type_decl(spv::Op op) { return op >= spv::OpTypeVoid && op <= spv::OpTypeForwardPointer; }

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

} // namespace

bool emulate_fp16(std::vector<uint32_t>& spirv, Fp16EmulationStats* stats) {
    Module m = parse(spirv);
    Fp16EmulationStats st;

    // --- Types: the 16-bit float, the values built on it, and everything that contains it.
    struct TypeInfo {
        spv::Op op;
        uint32_t width = 0;     // OpTypeFloat, OpTypeInt
        uint32_t component = 0; // OpTypeVector/Matrix: component/column type; OpTypeInt: signedness
        uint32_t count = 0;     // OpTypeVector: components
    };
    std::unordered_map<uint32_t, TypeInfo> types;
    std::set<uint32_t> halfish;     // types that contain a 16-bit float anywhere
    std::set<uint32_t> half_values; // the fp16 scalar and vector types: results that get rounded
    uint32_t half = 0, glsl_set = 0;
    std::unordered_map<uint32_t, uint32_t> value_type; // result id → its type
    for (const Inst& i : m.insts) {
        if (i.type) value_type[i.result] = i.type;
        if (i.op() == spv::OpExtInstImport && std::strcmp(reinterpret_cast<const char*>(&i.words[2]), "GLSL.std.450") == 0)
            glsl_set = i.result;
        if (!is_type_decl(i.op()) || !i.result) continue;
        TypeInfo t{i.op()};
        if (i.op() == spv::OpTypeFloat) t.width = i.words[2];
        if (i.op() == spv::OpTypeInt) {
            t.width = i.words[2];
            t.component = i.words[3];
        }
        if (i.op() == spv::OpTypeVector || i.op() == spv::OpTypeMatrix) {
            t.component = i.words[2];
            t.count = i.words[3];
        }
        types[i.result] = t;
        bool is_half = i.op() == spv::OpTypeFloat && t.width == 16;
        for (uint16_t s : i.id_slots) is_half |= halfish.count(i.words[s]) != 0;
        if (!is_half) continue;
        halfish.insert(i.result);
        if (i.op() == spv::OpTypeFloat) half = i.result;
        if (i.op() == spv::OpTypeFloat || (i.op() == spv::OpTypeVector && half_values.count(t.component)))
            half_values.insert(i.result);
        if (i.op() == spv::OpTypeMatrix) throw ShaderCompileError("fp16 emulation: 16-bit float matrices are not supported");
        if (i.op() == spv::OpTypeImage || i.op() == spv::OpTypeSampledImage)
            throw ShaderCompileError("fp16 emulation: images with a 16-bit float sampled type cannot be widened");
        if (i.op() == spv::OpTypePointer) {
            auto sc = spv::StorageClass(i.words[2]);
            if (sc != spv::StorageClassFunction && sc != spv::StorageClassPrivate && sc != spv::StorageClassWorkgroup)
                throw ShaderCompileError("fp16 emulation: a 16-bit float in storage class " + std::to_string(sc) +
                                         " (buffer, push constant or interface) cannot be widened: its layout "
                                         "would change");
        }
    }
    if (half_values.empty()) return false;
    if (!glsl_set) throw ShaderCompileError("fp16 emulation: the module imports no GLSL.std.450 (glslang always does)");
    auto is_f32_value = [&](uint32_t type) {
        auto it = types.find(type);
        if (it == types.end()) return false;
        if (it->second.op == spv::OpTypeVector) it = types.find(it->second.component);
        return it != types.end() && it->second.op == spv::OpTypeFloat && it->second.width == 32;
    };

    uint32_t bound = m.header[3];
    for (const Inst& i : m.insts) {
        if (i.op() == spv::OpExecutionMode && i.words.size() > 3 && i.words[3] == 16 &&
            i.words[2] >= spv::ExecutionModeDenormPreserve && i.words[2] <= spv::ExecutionModeRoundingModeRTZ)
            throw ShaderCompileError("fp16 emulation: 16-bit float-controls execution modes cannot be honoured");
        if (i.op() == spv::OpBitcast && (halfish.count(i.type) || halfish.count(value_type[i.words[3]])))
            throw ShaderCompileError("fp16 emulation: a bit cast of a 16-bit float cannot be widened");
        if ((i.op() == spv::OpSpecConstant || i.op() == spv::OpSpecConstantOp) && halfish.count(i.type))
            throw ShaderCompileError("fp16 emulation: 16-bit float specialization constants are not supported "
                                     "(the host would pass 2 bytes)");
    }

    // --- Declarations the rounding needs (uint and bool scalars/vectors, constants), found among
    // the module's or appended after its globals.
    std::vector<Inst> extra_globals;
    std::map<std::vector<uint32_t>, uint32_t> declared; // opcode + operands → id, for types
    for (const auto& [id, t] : types) {
        if (t.op == spv::OpTypeInt) declared[{spv::OpTypeInt, t.width, t.component}] = id;
        if (t.op == spv::OpTypeBool) declared[{spv::OpTypeBool}] = id;
        if (t.op == spv::OpTypeVector) declared[{spv::OpTypeVector, t.component, t.count}] = id;
    }
    auto type_decl = [&](spv::Op op, std::vector<uint32_t> operands, std::vector<uint16_t> slots) {
        std::vector<uint32_t> key = {uint32_t(op)};
        key.insert(key.end(), operands.begin(), operands.end());
        auto it = declared.find(key);
        if (it != declared.end()) return it->second;
        uint32_t id = bound++;
        operands.insert(operands.begin(), id);
        extra_globals.push_back(make(op, operands, std::move(slots), 0, id));
        return declared[key] = id;
    };
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> constants; // (type, bits) → id
    // A constant of `type` (scalar, or vector of the scalar `scalar`) with every component `bits`.
    auto constant = [&](uint32_t type, uint32_t scalar, uint32_t n, uint32_t bits) {
        auto scalar_constant = [&](uint32_t t) {
            auto [it, fresh] = constants.emplace(std::pair{t, bits}, 0);
            if (fresh) {
                it->second = bound++;
                extra_globals.push_back(make(spv::OpConstant, {t, it->second, bits}, {1}, t, it->second));
            }
            return it->second;
        };
        uint32_t c = scalar_constant(scalar);
        if (type == scalar) return c;
        auto [it, fresh] = constants.emplace(std::pair{type, bits}, 0);
        if (fresh) {
            it->second = bound++;
            std::vector<uint32_t> ops = {type, it->second};
            std::vector<uint16_t> slots = {1};
            for (uint32_t k = 0; k < n; ++k) {
                ops.push_back(c);
                slots.push_back(uint16_t(3 + k));
            }
            extra_globals.push_back(make(spv::OpConstantComposite, ops, slots, type, it->second));
        }
        return it->second;
    };

    // --- Function bodies and constants.
    std::vector<Inst> out;
    out.reserve(m.insts.size() * 4);
    size_t first_function = 0;
    std::unordered_map<uint32_t, uint32_t> renamed; // original result id → the fresh id of the unrounded value

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
    auto round_to_half = [&](uint32_t x, uint32_t type, uint32_t result) {
        uint32_t n = type == half ? 1 : types[type].count;
        uint32_t u32 = type_decl(spv::OpTypeInt, {32, 0}, {});
        uint32_t boolean = type_decl(spv::OpTypeBool, {}, {});
        uint32_t ut = n == 1 ? u32 : type_decl(spv::OpTypeVector, {u32, n}, {2});
        uint32_t bt = n == 1 ? boolean : type_decl(spv::OpTypeVector, {boolean, n}, {2});
        auto uc = [&](uint32_t v) { return constant(ut, u32, n, v); };
        auto fc = [&](float f) { return constant(type, half, n, std::bit_cast<uint32_t>(f)); };
        auto op = [&](spv::Op o, uint32_t t, std::vector<uint32_t> args, uint32_t id = 0) {
            if (!id) id = bound++;
            std::vector<uint32_t> words = {t, id};
            std::vector<uint16_t> slots = {1};
            for (uint32_t a : args) {
                words.push_back(a);
                slots.push_back(uint16_t(words.size()));
            }
            out.push_back(make(o, words, slots, t, id));
            return id;
        };
        uint32_t u = op(spv::OpBitcast, ut, {x});
        uint32_t a = op(spv::OpBitwiseAnd, ut, {u, uc(0x7fffffffu)});
        uint32_t sign = op(spv::OpBitwiseAnd, ut, {u, uc(0x80000000u)});
        uint32_t lsb = op(spv::OpBitwiseAnd, ut, {op(spv::OpShiftRightLogical, ut, {a, uc(13)}), uc(1)});
        uint32_t r = op(spv::OpIAdd, ut, {op(spv::OpIAdd, ut, {a, uc(0x0fffu)}), lsb});
        r = op(spv::OpBitwiseAnd, ut, {r, uc(0xffffe000u)});
        r = op(spv::OpSelect, ut, {op(spv::OpUGreaterThan, bt, {r, uc(0x477fe000u)}), uc(0x7f800000u), r});
        uint32_t scaled = op(spv::OpFMul, type, {op(spv::OpBitcast, type, {a}), fc(0x1p24f)});
        uint32_t k = bound++;
        out.push_back(make(spv::OpExtInst, {type, k, glsl_set, GLSLstd450RoundEven, scaled}, {1, 3, 5}, type, k));
        uint32_t sub = op(spv::OpBitcast, ut, {op(spv::OpFMul, type, {k, fc(0x1p-24f)})});
        r = op(spv::OpSelect, ut, {op(spv::OpULessThan, bt, {a, uc(0x38800000u)}), sub, r});
        r = op(spv::OpSelect, ut, {op(spv::OpUGreaterThan, bt, {a, uc(0x7f800000u)}), a, r});
        op(spv::OpBitcast, type, {op(spv::OpBitwiseOr, ut, {r, sign})}, result);
        ++st.rounded;
    };

    bool in_function = false;
    for (Inst& i : m.insts) {
        spv::Op op = i.op();
        if (op == spv::OpFunction && !in_function && !first_function) first_function = out.size();
        if (op == spv::OpFunction) in_function = true;
        if (op == spv::OpFunctionEnd) in_function = false;
        if (op == spv::OpConstant && half_values.count(i.type)) {
            i.words[3] = half_bits_to_float_bits(i.words[3] & 0xffff);
            ++st.constants;
        }
        if (op == spv::OpCapability && i.words[1] == spv::CapabilityFloat16) continue;
        if (op == spv::OpExtension &&
            std::strcmp(reinterpret_cast<const char*>(&i.words[1]), "SPV_AMD_gpu_shader_half_float") == 0)
            continue;
        if (!in_function || op == spv::OpFunction) {
            out.push_back(std::move(i));
            continue;
        }
        if (op == spv::OpFConvert && is_f32_value(i.type) && halfish.count(value_type[i.words[3]])) {
            i.words[0] = (i.words[0] & 0xffff0000u) | spv::OpCopyObject; // f16 → f32: the value is already an fp16
            out.push_back(std::move(i));
            continue;
        }
        if (!half_values.count(i.type) || is_exact(i)) {
            out.push_back(std::move(i));
            continue;
        }
        const uint32_t type = i.type, result = i.result;
        if (op == spv::OpFConvert && is_f32_value(value_type[i.words[3]])) {
            round_to_half(i.words[3], type, result); // f32 → f16 is the rounding itself
            continue;
        }
        if (op == spv::OpDot) {
            // Σ a_k·b_k from left to right, each product and each partial sum rounded to fp16.
            uint32_t a = i.words[3], b = i.words[4], n = types[value_type[a]].count, acc = 0;
            for (uint32_t k = 0; k < n; ++k) {
                uint32_t ak = bound++, bk = bound++, prod = bound++, rounded = bound++;
                out.push_back(make(spv::OpCompositeExtract, {type, ak, a, k}, {1, 3}, type, ak));
                out.push_back(make(spv::OpCompositeExtract, {type, bk, b, k}, {1, 3}, type, bk));
                out.push_back(make(spv::OpFMul, {type, prod, ak, bk}, {1, 3, 4}, type, prod));
                round_to_half(prod, type, rounded);
                if (k == 0) {
                    acc = rounded;
                    continue;
                }
                uint32_t sum = bound++, next = k + 1 == n ? result : bound++;
                out.push_back(make(spv::OpFAdd, {type, sum, acc, rounded}, {1, 3, 4}, type, sum));
                round_to_half(sum, type, next);
                acc = next;
            }
            ++st.dots_expanded;
            continue;
        }
        if (op == spv::OpExtInst && i.glsl_ext && i.words[4] == GLSLstd450FMix) {
            // mix(x, y, a) as GLSL defines it, x·(1 − a) + y·a, each operation rounded to fp16.
            uint32_t x = i.words[5], y = i.words[6], a = i.words[7], n = type == half ? 1 : types[type].count;
            uint32_t one = constant(type, half, n, std::bit_cast<uint32_t>(1.0f));
            auto rounded_op = [&](spv::Op o, uint32_t l, uint32_t r, uint32_t id) {
                uint32_t raw = bound++;
                out.push_back(make(o, {type, raw, l, r}, {1, 3, 4}, type, raw));
                round_to_half(raw, type, id ? id : (id = bound++));
                return id;
            };
            uint32_t keep = rounded_op(spv::OpFMul, x, rounded_op(spv::OpFSub, one, a, 0), 0);
            rounded_op(spv::OpFAdd, keep, rounded_op(spv::OpFMul, y, a, 0), result);
            ++st.mixes_expanded;
            continue;
        }
        uint32_t fresh = bound++;
        i.words[2] = fresh;
        i.result = fresh;
        renamed[result] = fresh;
        out.push_back(std::move(i));
        round_to_half(fresh, type, result);
    }
    out.insert(out.begin() + std::ptrdiff_t(first_function), std::make_move_iterator(extra_globals.begin()),
               std::make_move_iterator(extra_globals.end()));

    // --- Types: 16-bit float → 32-bit, then merge the duplicates that creates. A type that now
    // equals an earlier one (same opcode and operands once ids are remapped) takes its id.
    std::unordered_map<uint32_t, uint32_t> remap;
    std::set<uint32_t> removed;
    std::map<std::vector<uint32_t>, uint32_t> seen;
    auto mapped = [&](uint32_t id) {
        auto it = remap.find(id);
        return it == remap.end() ? id : it->second;
    };
    for (Inst& i : out) {
        if (!is_type_decl(i.op()) || !i.result) continue;
        if (i.op() == spv::OpTypeFloat && i.words[2] == 16) i.words[2] = 32;
        for (uint16_t s : i.id_slots) i.words[s] = mapped(i.words[s]);
        // Structs and arrays may legally repeat (and carry their own decorations); pointers too, and
        // only those this pass made equal are merged.
        spv::Op op = i.op();
        if (op == spv::OpTypeStruct || op == spv::OpTypeArray || op == spv::OpTypeRuntimeArray || op == spv::OpTypeForwardPointer)
            continue;
        std::vector<uint32_t> key(i.words.begin(), i.words.end());
        key.erase(key.begin() + 1); // the result id
        auto [it, inserted] = seen.emplace(key, i.result);
        if (!inserted && (op != spv::OpTypePointer || halfish.count(i.result))) {
            remap[i.result] = it->second;
            removed.insert(i.result);
        }
    }
    std::vector<uint32_t> words = {m.header[0], m.header[1], m.header[2], bound, m.header[4]};
    for (Inst& i : out) {
        if (removed.count(i.result)) continue;
        spv::Op op = i.op();
        bool annotates = op == spv::OpName || op == spv::OpMemberName || op == spv::OpDecorate || op == spv::OpMemberDecorate ||
                         op == spv::OpDecorateId || op == spv::OpDecorateString || op == spv::OpMemberDecorateString;
        if (annotates && removed.count(i.words[1])) continue;
        // precise (NoContraction) belongs to the arithmetic, which now carries the fresh id.
        if (op == spv::OpDecorate && i.words[2] == spv::DecorationNoContraction && renamed.count(i.words[1]))
            i.words[1] = renamed[i.words[1]];
        for (uint16_t s : i.id_slots) i.words[s] = mapped(i.words[s]);
        words.insert(words.end(), i.words.begin(), i.words.end());
    }
    if (std::string why = validate_spirv(words); !why.empty())
        throw ShaderCompileError("fp16 emulation produced invalid SPIR-V (a bug of the pass): " + why);
    spirv = std::move(words);
    if (stats) *stats = st;
    return true;
}

} // namespace iblcheck::vk
