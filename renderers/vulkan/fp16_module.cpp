// The fp16 emulation pass's bookkeeping: parsing, the type table, the declarations it adds, and the
// widening and merging of types at the end (fp16_module.h). The rewriting is fp16_emulation.cpp.
#include "fp16_module.h"

#include <spirv-tools/libspirv.hpp>

#include <cstring>
#include <string>

#include "kernel/errors.h"

namespace iblcheck::vk::fp16 {

Inst make(spv::Op op, std::vector<uint32_t> operands, std::vector<uint16_t> id_slots, uint32_t type, uint32_t result) {
    Inst i;
    i.words.push_back(uint32_t(operands.size() + 1) << 16 | uint32_t(op));
    i.words.insert(i.words.end(), operands.begin(), operands.end());
    i.id_slots = std::move(id_slots);
    i.type = type;
    i.result = result;
    return i;
}

namespace {

spv_result_t on_header(void* user, spv_endianness_t, uint32_t magic, uint32_t version, uint32_t generator, uint32_t bound,
                       uint32_t schema) {
    static_cast<Module*>(user)->header = {magic, version, generator, bound, schema};
    return SPV_SUCCESS;
}

spv_result_t on_instruction(void* user, const spv_parsed_instruction_t* p) {
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
}

bool is_type_decl(spv::Op op) { return op >= spv::OpTypeVoid && op <= spv::OpTypeForwardPointer; }

TypeInfo type_info(const Inst& i) {
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
    return t;
}

// A type that holds a 16-bit float (`i`, described by `t`) must be one the pass can widen.
void require_widenable(const Inst& i) {
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

bool is_annotation(spv::Op op) {
    return op == spv::OpName || op == spv::OpMemberName || op == spv::OpDecorate || op == spv::OpMemberDecorate ||
           op == spv::OpDecorateId || op == spv::OpDecorateString || op == spv::OpMemberDecorateString;
}

// The outcome of widening the types: merged type id → the id it merged into.
struct TypeMerge {
    std::unordered_map<uint32_t, uint32_t> remap;
    std::set<uint32_t> removed;
    uint32_t mapped(uint32_t id) const {
        auto it = remap.find(id);
        return it == remap.end() ? id : it->second;
    }
};

// 16-bit float → 32-bit, then a type that now equals an earlier one (same opcode and operands once
// ids are remapped) takes its id.
TypeMerge widen_and_merge_types(std::vector<Inst>& insts, const std::set<uint32_t>& halfish) {
    TypeMerge merge;
    std::map<std::vector<uint32_t>, uint32_t> seen;
    for (Inst& i : insts) {
        if (!is_type_decl(i.op()) || !i.result) continue;
        if (i.op() == spv::OpTypeFloat && i.words[2] == 16) i.words[2] = 32;
        for (uint16_t s : i.id_slots) i.words[s] = merge.mapped(i.words[s]);
        // Structs and arrays may legally repeat (and carry their own decorations); pointers too, and
        // only those this pass made equal are merged.
        spv::Op op = i.op();
        if (op == spv::OpTypeStruct || op == spv::OpTypeArray || op == spv::OpTypeRuntimeArray || op == spv::OpTypeForwardPointer)
            continue;
        std::vector<uint32_t> key(i.words.begin(), i.words.end());
        key.erase(key.begin() + 1); // the result id
        auto [it, inserted] = seen.emplace(key, i.result);
        if (!inserted && (op != spv::OpTypePointer || halfish.count(i.result))) {
            merge.remap[i.result] = it->second;
            merge.removed.insert(i.result);
        }
    }
    return merge;
}

} // namespace

Module parse(const std::vector<uint32_t>& spirv) {
    Module m;
    spv_context ctx = spvContextCreate(SPV_ENV_UNIVERSAL_1_6);
    spv_diagnostic diag = nullptr;
    spv_result_t r = spvBinaryParse(ctx, &m, spirv.data(), spirv.size(), on_header, on_instruction, &diag);
    std::string why = diag && diag->error ? diag->error : "";
    spvDiagnosticDestroy(diag);
    spvContextDestroy(ctx);
    if (r != SPV_SUCCESS) throw ShaderCompileError("fp16 emulation: cannot parse the SPIR-V: " + why);
    return m;
}

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

uint32_t TypeTable::type_of(uint32_t id) const {
    auto it = value_type.find(id);
    return it == value_type.end() ? 0 : it->second;
}

uint32_t TypeTable::count_of(uint32_t type) const {
    auto it = types.find(type);
    return it == types.end() ? 0 : it->second.count;
}

uint32_t TypeTable::components(uint32_t type) const { return type == half ? 1 : count_of(type); }

bool TypeTable::is_f32_value(uint32_t type) const {
    auto it = types.find(type);
    if (it == types.end()) return false;
    if (it->second.op == spv::OpTypeVector) it = types.find(it->second.component);
    return it != types.end() && it->second.op == spv::OpTypeFloat && it->second.width == 32;
}

TypeTable scan_types(const Module& m) {
    TypeTable t;
    for (const Inst& i : m.insts) {
        if (i.type) t.value_type[i.result] = i.type;
        if (i.op() == spv::OpExtInstImport && std::strcmp(reinterpret_cast<const char*>(&i.words[2]), "GLSL.std.450") == 0)
            t.glsl_set = i.result;
        if (!is_type_decl(i.op()) || !i.result) continue;
        TypeInfo info = type_info(i);
        t.types[i.result] = info;
        bool is_half = i.op() == spv::OpTypeFloat && info.width == 16;
        for (uint16_t s : i.id_slots) is_half |= t.halfish.count(i.words[s]) != 0;
        if (!is_half) continue;
        t.halfish.insert(i.result);
        if (i.op() == spv::OpTypeFloat) t.half = i.result;
        if (i.op() == spv::OpTypeFloat || (i.op() == spv::OpTypeVector && t.half_values.count(info.component)))
            t.half_values.insert(i.result);
        require_widenable(i);
    }
    return t;
}

void reject_unwidenable_uses(const Module& m, const TypeTable& t) {
    for (const Inst& i : m.insts) {
        if (i.op() == spv::OpExecutionMode && i.words.size() > 3 && i.words[3] == 16 &&
            i.words[2] >= spv::ExecutionModeDenormPreserve && i.words[2] <= spv::ExecutionModeRoundingModeRTZ)
            throw ShaderCompileError("fp16 emulation: 16-bit float-controls execution modes cannot be honoured");
        if (i.op() == spv::OpBitcast && (t.halfish.count(i.type) || t.halfish.count(t.type_of(i.words[3]))))
            throw ShaderCompileError("fp16 emulation: a bit cast of a 16-bit float cannot be widened");
        if ((i.op() == spv::OpSpecConstant || i.op() == spv::OpSpecConstantOp) && t.halfish.count(i.type))
            throw ShaderCompileError("fp16 emulation: 16-bit float specialization constants are not supported "
                                     "(the host would pass 2 bytes)");
    }
}

Declarations::Declarations(const TypeTable& t, uint32_t bound) : bound_(bound) {
    for (const auto& [id, type] : t.types) {
        if (type.op == spv::OpTypeInt) declared_[{spv::OpTypeInt, type.width, type.component}] = id;
        if (type.op == spv::OpTypeBool) declared_[{spv::OpTypeBool}] = id;
        if (type.op == spv::OpTypeVector) declared_[{spv::OpTypeVector, type.component, type.count}] = id;
    }
}

uint32_t Declarations::type_decl(spv::Op op, std::vector<uint32_t> operands, std::vector<uint16_t> slots) {
    std::vector<uint32_t> key = {uint32_t(op)};
    key.insert(key.end(), operands.begin(), operands.end());
    auto it = declared_.find(key);
    if (it != declared_.end()) return it->second;
    uint32_t id = bound_++;
    operands.insert(operands.begin(), id);
    globals_.push_back(make(op, operands, std::move(slots), 0, id));
    return declared_[key] = id;
}

uint32_t Declarations::scalar_constant(uint32_t type, uint32_t bits) {
    auto [it, fresh] = constants_.emplace(std::pair{type, bits}, 0);
    if (fresh) {
        it->second = bound_++;
        globals_.push_back(make(spv::OpConstant, {type, it->second, bits}, {1}, type, it->second));
    }
    return it->second;
}

uint32_t Declarations::constant(uint32_t type, uint32_t scalar, uint32_t n, uint32_t bits) {
    uint32_t c = scalar_constant(scalar, bits);
    if (type == scalar) return c;
    auto [it, fresh] = constants_.emplace(std::pair{type, bits}, 0);
    if (fresh) {
        it->second = bound_++;
        std::vector<uint32_t> ops = {type, it->second};
        std::vector<uint16_t> slots = {1};
        for (uint32_t k = 0; k < n; ++k) {
            ops.push_back(c);
            slots.push_back(uint16_t(3 + k));
        }
        globals_.push_back(make(spv::OpConstantComposite, ops, slots, type, it->second));
    }
    return it->second;
}

std::vector<uint32_t> assemble_widened(std::vector<Inst>& insts, const std::vector<uint32_t>& header, uint32_t bound,
                                       const std::set<uint32_t>& halfish, const std::unordered_map<uint32_t, uint32_t>& renamed) {
    TypeMerge merge = widen_and_merge_types(insts, halfish);
    std::vector<uint32_t> words = {header[0], header[1], header[2], bound, header[4]};
    for (Inst& i : insts) {
        if (merge.removed.count(i.result)) continue;
        spv::Op op = i.op();
        if (is_annotation(op) && merge.removed.count(i.words[1])) continue;
        // precise (NoContraction) belongs to the arithmetic, which now carries the fresh id.
        if (op == spv::OpDecorate && i.words[2] == spv::DecorationNoContraction)
            if (auto it = renamed.find(i.words[1]); it != renamed.end()) i.words[1] = it->second;
        for (uint16_t s : i.id_slots) i.words[s] = merge.mapped(i.words[s]);
        words.insert(words.end(), i.words.begin(), i.words.end());
    }
    return words;
}

} // namespace iblcheck::vk::fp16
