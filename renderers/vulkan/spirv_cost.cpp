#include "spirv_cost.h"

#include <glslang/SPIRV/spirv.hpp>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "harness/common/errors.h"

namespace iblcheck::vk {

namespace {

using Inst = std::vector<uint32_t>; // one instruction, word 0 included

spv::Op opcode(const Inst& i) { return spv::Op(i[0] & 0xffffu); }

Inst make(spv::Op op, std::initializer_list<uint32_t> operands) {
    Inst i;
    i.reserve(operands.size() + 1);
    i.push_back(uint32_t(operands.size() + 1) << 16 | uint32_t(op));
    i.insert(i.end(), operands);
    return i;
}

struct Module {
    std::vector<uint32_t> header; // magic, version, generator, bound, schema
    std::vector<Inst> insts;
};

Module parse(const std::vector<uint32_t>& spirv) {
    if (spirv.size() < 5 || spirv[0] != spv::MagicNumber) throw Error("SPIR-V instrumentation: not a SPIR-V module");
    Module m;
    m.header.assign(spirv.begin(), spirv.begin() + 5);
    for (size_t w = 5; w < spirv.size();) {
        size_t n = spirv[w] >> 16;
        if (n == 0 || w + n > spirv.size())
            throw Error("SPIR-V instrumentation: malformed instruction at word " + std::to_string(w));
        m.insts.emplace_back(spirv.begin() + long(w), spirv.begin() + long(w + n));
        w += n;
    }
    return m;
}

bool is_debug_line(spv::Op op) { return op == spv::OpLine || op == spv::OpNoLine; }

// Instructions of the logical layout's preamble (capabilities through annotations): whatever
// follows them, up to the first OpFunction, is types, constants and global variables.
bool in_preamble(spv::Op op) {
    switch (op) {
    case spv::OpCapability:
    case spv::OpExtension:
    case spv::OpExtInstImport:
    case spv::OpMemoryModel:
    case spv::OpEntryPoint:
    case spv::OpExecutionMode:
    case spv::OpExecutionModeId:
    case spv::OpString:
    case spv::OpSourceExtension:
    case spv::OpSource:
    case spv::OpSourceContinued:
    case spv::OpName:
    case spv::OpMemberName:
    case spv::OpModuleProcessed:
    case spv::OpDecorate:
    case spv::OpMemberDecorate:
    case spv::OpDecorationGroup:
    case spv::OpGroupDecorate:
    case spv::OpGroupMemberDecorate:
    case spv::OpDecorateId:
    case spv::OpDecorateString:
    case spv::OpMemberDecorateString: return true;
    default: return false;
    }
}

// A function body's blocks as [begin, end) instruction ranges, OpLabel first. A block runs to
// the next OpLabel or the OpFunctionEnd: every block ends in its terminator, so no list of
// terminators is needed.
struct Block {
    size_t begin, end;
    bool first;
};
std::vector<Block> blocks_of_function(const std::vector<Inst>& insts, size_t fn_begin, size_t& fn_end) {
    std::vector<Block> out;
    size_t i = fn_begin + 1;
    while (i < insts.size() && opcode(insts[i]) != spv::OpFunctionEnd) {
        if (opcode(insts[i]) != spv::OpLabel) {
            ++i; // OpFunctionParameter (or a stray debug line before the first label)
            continue;
        }
        size_t j = i + 1;
        while (j < insts.size() && opcode(insts[j]) != spv::OpLabel && opcode(insts[j]) != spv::OpFunctionEnd) ++j;
        out.push_back({i, j, out.empty()});
        i = j;
    }
    if (i >= insts.size()) throw Error("SPIR-V instrumentation: function without OpFunctionEnd");
    fn_end = i;
    return out;
}

uint32_t static_count(const std::vector<Inst>& insts, const Block& b) {
    uint32_t n = 0;
    for (size_t i = b.begin + 1; i < b.end; ++i) n += !is_debug_line(opcode(insts[i]));
    return n;
}

} // namespace

std::vector<std::vector<uint32_t>> block_instruction_counts(const std::vector<uint32_t>& spirv) {
    Module m = parse(spirv);
    std::vector<std::vector<uint32_t>> out;
    for (size_t i = 0; i < m.insts.size(); ++i) {
        if (opcode(m.insts[i]) != spv::OpFunction) continue;
        size_t end = i;
        std::vector<uint32_t> counts;
        for (const Block& b : blocks_of_function(m.insts, i, end)) counts.push_back(static_count(m.insts, b));
        out.push_back(std::move(counts));
        i = end;
    }
    return out;
}

std::vector<uint32_t> instrument_instruction_count(const std::vector<uint32_t>& spirv) {
    Module m = parse(spirv);
    if (m.header[1] < 0x00010300u)
        throw Error("SPIR-V instrumentation: needs SPIR-V 1.3 or later (the StorageBuffer class), module is 1." +
                    std::to_string((m.header[1] >> 8) & 0xffu));
    uint32_t bound = m.header[3];
    auto fresh = [&] { return bound++; };

    // What the module already has: reused where SPIR-V forbids duplicates (integer types) or
    // allows reuse (pointer types); the binding must be free.
    std::set<spv::Capability> caps;
    std::set<uint32_t> entry_functions;
    std::map<uint32_t, uint32_t> set_of, binding_of;
    uint32_t u64 = 0, u32 = 0, ptr_private_u64 = 0, ptr_sb_u64 = 0;
    size_t last_cap = 0, last_name = 0, first_global = 0, first_function = m.insts.size();
    for (size_t i = 0; i < m.insts.size(); ++i) {
        const Inst& in = m.insts[i];
        spv::Op op = opcode(in);
        if (op == spv::OpCapability) {
            caps.insert(spv::Capability(in[1]));
            last_cap = i;
        } else if (op == spv::OpEntryPoint) {
            entry_functions.insert(in[2]);
        } else if (op == spv::OpName || op == spv::OpMemberName) {
            last_name = i;
        } else if (op == spv::OpDecorate && in.size() >= 4 && in[2] == spv::DecorationDescriptorSet) {
            set_of[in[1]] = in[3];
        } else if (op == spv::OpDecorate && in.size() >= 4 && in[2] == spv::DecorationBinding) {
            binding_of[in[1]] = in[3];
        } else if (op == spv::OpTypeInt && in[3] == 0 && in[2] == 64) {
            u64 = in[1];
        } else if (op == spv::OpTypeInt && in[3] == 0 && in[2] == 32) {
            u32 = in[1];
        } else if (op == spv::OpFunction && first_function == m.insts.size()) {
            first_function = i;
        }
        if (!first_global && !in_preamble(op)) first_global = i;
    }
    if (!first_global || first_global > first_function) first_global = first_function;
    if (entry_functions.empty()) throw Error("SPIR-V instrumentation: module has no entry point");
    for (auto [id, binding] : binding_of)
        if (binding == kCostBinding && set_of.count(id) && set_of[id] == 0)
            throw ShaderCompileError("instruction counting needs descriptor set 0 binding " + std::to_string(kCostBinding) +
                                     ", which the shader already uses");
    for (size_t i = first_global; i < first_function; ++i) {
        const Inst& in = m.insts[i];
        if (opcode(in) != spv::OpTypePointer || !u64 || in[3] != u64) continue;
        if (in[2] == spv::StorageClassPrivate) ptr_private_u64 = in[1];
        if (in[2] == spv::StorageClassStorageBuffer) ptr_sb_u64 = in[1];
    }

    std::vector<Inst> caps_add, names_add, decorations_add, globals_add;
    for (spv::Capability c : {spv::CapabilityInt64, spv::CapabilityInt64Atomics})
        if (!caps.count(c)) caps_add.push_back(make(spv::OpCapability, {uint32_t(c)}));
    if (!u64) {
        u64 = fresh();
        globals_add.push_back(make(spv::OpTypeInt, {u64, 64, 0}));
    }
    if (!u32) {
        u32 = fresh();
        globals_add.push_back(make(spv::OpTypeInt, {u32, 32, 0}));
    }
    if (!ptr_private_u64) {
        ptr_private_u64 = fresh();
        globals_add.push_back(make(spv::OpTypePointer, {ptr_private_u64, spv::StorageClassPrivate, u64}));
    }
    if (!ptr_sb_u64) {
        ptr_sb_u64 = fresh();
        globals_add.push_back(make(spv::OpTypePointer, {ptr_sb_u64, spv::StorageClassStorageBuffer, u64}));
    }
    uint32_t block_type = fresh(), ptr_block = fresh(), buffer = fresh(), counter = fresh();
    uint32_t zero64 = fresh(), index0 = fresh(), scope_device = fresh(), relaxed = fresh();
    globals_add.push_back(make(spv::OpTypeStruct, {block_type, u64}));
    globals_add.push_back(make(spv::OpTypePointer, {ptr_block, spv::StorageClassStorageBuffer, block_type}));
    globals_add.push_back(make(spv::OpConstant, {u64, zero64, 0, 0}));
    globals_add.push_back(make(spv::OpConstant, {u32, index0, 0}));
    globals_add.push_back(make(spv::OpConstant, {u32, scope_device, spv::ScopeDevice}));
    globals_add.push_back(make(spv::OpConstant, {u32, relaxed, spv::MemorySemanticsMaskNone}));
    globals_add.push_back(make(spv::OpVariable, {ptr_block, buffer, spv::StorageClassStorageBuffer}));
    // Private variables are per invocation; the initializer zeroes each one at its start.
    globals_add.push_back(make(spv::OpVariable, {ptr_private_u64, counter, spv::StorageClassPrivate, zero64}));
    decorations_add.push_back(make(spv::OpDecorate, {block_type, spv::DecorationBlock}));
    decorations_add.push_back(make(spv::OpMemberDecorate, {block_type, 0, spv::DecorationOffset, 0}));
    decorations_add.push_back(make(spv::OpDecorate, {buffer, spv::DecorationDescriptorSet, 0}));
    decorations_add.push_back(make(spv::OpDecorate, {buffer, spv::DecorationBinding, kCostBinding}));
    if (last_name) {
        auto name = [&](uint32_t id, const char* s) {
            Inst i = {0, id};
            std::string str(s);
            str.resize((str.size() / 4 + 1) * 4, '\0');
            for (size_t k = 0; k < str.size(); k += 4)
                i.push_back(uint32_t(uint8_t(str[k])) | uint32_t(uint8_t(str[k + 1])) << 8 | uint32_t(uint8_t(str[k + 2])) << 16 |
                            uint32_t(uint8_t(str[k + 3])) << 24);
            i[0] = uint32_t(i.size()) << 16 | spv::OpName;
            names_add.push_back(i);
        };
        name(counter, "iblcheck_instructions");
        name(buffer, "iblcheck_instruction_total");
    }
    std::map<uint32_t, uint32_t> count_constant; // static count -> uint64 constant id
    auto constant = [&](uint32_t n) {
        auto [it, added] = count_constant.emplace(n, 0);
        if (added) {
            it->second = fresh();
            globals_add.push_back(make(spv::OpConstant, {u64, it->second, n, 0}));
        }
        return it->second;
    };

    // Since SPIR-V 1.4 an entry point lists every global variable it uses.
    if (m.header[1] >= 0x00010400u)
        for (Inst& in : m.insts)
            if (opcode(in) == spv::OpEntryPoint) {
                in.push_back(counter);
                in.push_back(buffer);
                in[0] = uint32_t(in.size()) << 16 | spv::OpEntryPoint;
            }

    // The function bodies, rewritten block by block.
    std::vector<Inst> body;
    for (size_t i = first_function; i < m.insts.size(); ++i) {
        if (opcode(m.insts[i]) != spv::OpFunction)
            throw Error("SPIR-V instrumentation: unexpected instruction between functions");
        bool entry = entry_functions.count(m.insts[i][2]) > 0;
        size_t end = i;
        std::vector<Block> blocks = blocks_of_function(m.insts, i, end);
        size_t copied = i;
        for (const Block& b : blocks) {
            // OpPhi must open a block and OpVariable the function's first one: count after them.
            size_t at = b.begin + 1;
            while (at < b.end && (opcode(m.insts[at]) == spv::OpPhi || is_debug_line(opcode(m.insts[at])) ||
                                  (b.first && opcode(m.insts[at]) == spv::OpVariable)))
                ++at;
            for (; copied < at; ++copied) body.push_back(m.insts[copied]);
            uint32_t n = static_count(m.insts, b);
            uint32_t loaded = fresh(), sum = fresh();
            body.push_back(make(spv::OpLoad, {u64, loaded, counter}));
            body.push_back(make(spv::OpIAdd, {u64, sum, loaded, constant(n)}));
            body.push_back(make(spv::OpStore, {counter, sum}));
            size_t terminator = b.end - 1;
            spv::Op term = opcode(m.insts[terminator]);
            // An invocation ends at a return of its entry point, or wherever a fragment is
            // discarded (OpKill, OpTerminateInvocation: in any function).
            if ((entry && term == spv::OpReturn) || term == spv::OpKill || term == spv::OpTerminateInvocation) {
                for (; copied < terminator; ++copied) body.push_back(m.insts[copied]);
                uint32_t total = fresh(), ptr = fresh(), old = fresh();
                body.push_back(make(spv::OpLoad, {u64, total, counter}));
                body.push_back(make(spv::OpAccessChain, {ptr_sb_u64, ptr, buffer, index0}));
                body.push_back(make(spv::OpAtomicIAdd, {u64, old, ptr, scope_device, relaxed, total}));
            }
        }
        for (; copied <= end; ++copied) body.push_back(m.insts[copied]);
        i = end;
    }

    std::vector<uint32_t> out = m.header;
    out[3] = bound;
    auto emit = [&](const std::vector<Inst>& v) {
        for (const Inst& in : v) out.insert(out.end(), in.begin(), in.end());
    };
    for (size_t i = 0; i < first_function; ++i) {
        if (i == first_global) emit(decorations_add);
        out.insert(out.end(), m.insts[i].begin(), m.insts[i].end());
        if (i == last_cap) emit(caps_add);
        if (i == last_name && last_name) emit(names_add);
    }
    if (first_global == first_function) emit(decorations_add);
    emit(globals_add);
    emit(body);
    return out;
}

uint64_t count_dispatch_instructions(Context& ctx, const ComputePipeline& counted, std::vector<Binding> bindings,
                                     const void* push, uint32_t push_bytes, uint32_t gx, uint32_t gy, uint32_t gz) {
    Buffer total = ctx.create_buffer(sizeof(uint64_t)); // zeroed at creation
    bindings.push_back(Binding::storage_buffer(kCostBinding, total));
    ctx.submit([&](VkCommandBuffer cmd) {
        counted.dispatch(cmd, bindings, push, push_bytes, gx, gy, gz);
        Context::barrier(cmd);
    });
    return *total.as<uint64_t>();
}

} // namespace iblcheck::vk
