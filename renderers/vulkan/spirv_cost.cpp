#include "spirv_cost.h"

#include <glslang/SPIRV/spirv.hpp>

#include <algorithm>
#include <map>
#include <set>
#include <string>

#include "kernel/errors.h"

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

// What the module already has: reused where SPIR-V forbids duplicates (integer types) or allows
// reuse (pointer types), and where the additions go in the logical layout.
struct Survey {
    std::set<spv::Capability> caps;
    std::set<uint32_t> entry_functions;
    uint32_t u64 = 0, u32 = 0, ptr_private_u64 = 0, ptr_sb_u64 = 0;
    size_t last_cap = 0, last_name = 0, first_global = 0, first_function = 0;
};

// Throws ShaderCompileError when (set 0, binding kCostBinding) is taken.
void require_cost_binding_free(const std::map<uint32_t, uint32_t>& set_of, const std::map<uint32_t, uint32_t>& binding_of) {
    for (auto [id, binding] : binding_of)
        if (binding == kCostBinding && set_of.count(id) && set_of.at(id) == 0)
            throw ShaderCompileError("instruction counting needs descriptor set 0 binding " + std::to_string(kCostBinding) +
                                     ", which the shader already uses");
}

// The uint64 pointer types (Private, StorageBuffer) among the globals.
void find_u64_pointers(const Module& m, Survey& s) {
    for (size_t i = s.first_global; i < s.first_function; ++i) {
        const Inst& in = m.insts[i];
        if (opcode(in) != spv::OpTypePointer || !s.u64 || in[3] != s.u64) continue;
        if (in[2] == spv::StorageClassPrivate) s.ptr_private_u64 = in[1];
        if (in[2] == spv::StorageClassStorageBuffer) s.ptr_sb_u64 = in[1];
    }
}

Survey survey(const Module& m) {
    Survey s;
    s.first_function = m.insts.size();
    std::map<uint32_t, uint32_t> set_of, binding_of;
    for (size_t i = 0; i < m.insts.size(); ++i) {
        const Inst& in = m.insts[i];
        spv::Op op = opcode(in);
        if (op == spv::OpCapability) {
            s.caps.insert(spv::Capability(in[1]));
            s.last_cap = i;
        } else if (op == spv::OpEntryPoint) {
            s.entry_functions.insert(in[2]);
        } else if (op == spv::OpName || op == spv::OpMemberName) {
            s.last_name = i;
        } else if (op == spv::OpDecorate && in.size() >= 4 && in[2] == spv::DecorationDescriptorSet) {
            set_of[in[1]] = in[3];
        } else if (op == spv::OpDecorate && in.size() >= 4 && in[2] == spv::DecorationBinding) {
            binding_of[in[1]] = in[3];
        } else if (op == spv::OpTypeInt && in[3] == 0 && in[2] == 64) {
            s.u64 = in[1];
        } else if (op == spv::OpTypeInt && in[3] == 0 && in[2] == 32) {
            s.u32 = in[1];
        } else if (op == spv::OpFunction && s.first_function == m.insts.size()) {
            s.first_function = i;
        }
        if (!s.first_global && !in_preamble(op)) s.first_global = i;
    }
    if (!s.first_global || s.first_global > s.first_function) s.first_global = s.first_function;
    if (s.entry_functions.empty()) throw Error("SPIR-V instrumentation: module has no entry point");
    require_cost_binding_free(set_of, binding_of);
    find_u64_pointers(m, s);
    return s;
}

// An OpName of `id`: the string's bytes, nul-terminated and padded to whole words.
Inst name_instruction(uint32_t id, const char* s) {
    Inst i = {0, id};
    std::string str(s);
    str.resize((str.size() / 4 + 1) * 4, '\0');
    for (size_t k = 0; k < str.size(); k += 4)
        i.push_back(uint32_t(uint8_t(str[k])) | uint32_t(uint8_t(str[k + 1])) << 8 | uint32_t(uint8_t(str[k + 2])) << 16 |
                    uint32_t(uint8_t(str[k + 3])) << 24);
    i[0] = uint32_t(i.size()) << 16 | spv::OpName;
    return i;
}

// The counter and what it needs: the ids, and the instructions by where they go in the module.
struct Counter {
    explicit Counter(uint32_t first_free_id) : bound(first_free_id) {}
    uint32_t bound;
    uint32_t u64 = 0, u32 = 0, ptr_private_u64 = 0, ptr_sb_u64 = 0;
    uint32_t block_type = 0, ptr_block = 0, buffer = 0, counter = 0, zero64 = 0, index0 = 0, scope_device = 0, relaxed = 0;
    std::vector<Inst> caps_add, names_add, decorations_add, globals_add;
    std::map<uint32_t, uint32_t> count_constant; // static count -> uint64 constant id

    uint32_t fresh() { return bound++; }
    // The uint64 constant `n`, declared on first use.
    uint32_t constant(uint32_t n) {
        auto [it, added] = count_constant.emplace(n, 0);
        if (added) {
            it->second = fresh();
            globals_add.push_back(make(spv::OpConstant, {u64, it->second, n, 0}));
        }
        return it->second;
    }
};

// The Int64 capabilities, and the uint64/uint32 types and uint64 pointers the module lacks.
void declare_missing_types(const Survey& s, Counter& c) {
    for (spv::Capability cap : {spv::CapabilityInt64, spv::CapabilityInt64Atomics})
        if (!s.caps.count(cap)) c.caps_add.push_back(make(spv::OpCapability, {uint32_t(cap)}));
    c.u64 = s.u64 ? s.u64 : c.fresh();
    if (!s.u64) c.globals_add.push_back(make(spv::OpTypeInt, {c.u64, 64, 0}));
    c.u32 = s.u32 ? s.u32 : c.fresh();
    if (!s.u32) c.globals_add.push_back(make(spv::OpTypeInt, {c.u32, 32, 0}));
    c.ptr_private_u64 = s.ptr_private_u64 ? s.ptr_private_u64 : c.fresh();
    if (!s.ptr_private_u64)
        c.globals_add.push_back(make(spv::OpTypePointer, {c.ptr_private_u64, spv::StorageClassPrivate, c.u64}));
    c.ptr_sb_u64 = s.ptr_sb_u64 ? s.ptr_sb_u64 : c.fresh();
    if (!s.ptr_sb_u64) c.globals_add.push_back(make(spv::OpTypePointer, {c.ptr_sb_u64, spv::StorageClassStorageBuffer, c.u64}));
}

// The per-invocation counter, the buffer at (set 0, kCostBinding) it is added to, their
// constants, decorations and (when the module names things) names.
void declare_counter(const Survey& s, Counter& c) {
    for (uint32_t* id : {&c.block_type, &c.ptr_block, &c.buffer, &c.counter, &c.zero64, &c.index0, &c.scope_device, &c.relaxed})
        *id = c.fresh(); // in this order: the ids are part of the output
    c.globals_add.push_back(make(spv::OpTypeStruct, {c.block_type, c.u64}));
    c.globals_add.push_back(make(spv::OpTypePointer, {c.ptr_block, spv::StorageClassStorageBuffer, c.block_type}));
    c.globals_add.push_back(make(spv::OpConstant, {c.u64, c.zero64, 0, 0}));
    c.globals_add.push_back(make(spv::OpConstant, {c.u32, c.index0, 0}));
    c.globals_add.push_back(make(spv::OpConstant, {c.u32, c.scope_device, spv::ScopeDevice}));
    c.globals_add.push_back(make(spv::OpConstant, {c.u32, c.relaxed, spv::MemorySemanticsMaskNone}));
    c.globals_add.push_back(make(spv::OpVariable, {c.ptr_block, c.buffer, spv::StorageClassStorageBuffer}));
    // Private variables are per invocation; the initializer zeroes each one at its start.
    c.globals_add.push_back(make(spv::OpVariable, {c.ptr_private_u64, c.counter, spv::StorageClassPrivate, c.zero64}));
    c.decorations_add.push_back(make(spv::OpDecorate, {c.block_type, spv::DecorationBlock}));
    c.decorations_add.push_back(make(spv::OpMemberDecorate, {c.block_type, 0, spv::DecorationOffset, 0}));
    c.decorations_add.push_back(make(spv::OpDecorate, {c.buffer, spv::DecorationDescriptorSet, 0}));
    c.decorations_add.push_back(make(spv::OpDecorate, {c.buffer, spv::DecorationBinding, kCostBinding}));
    if (s.last_name) {
        c.names_add.push_back(name_instruction(c.counter, "iblcheck_instructions"));
        c.names_add.push_back(name_instruction(c.buffer, "iblcheck_instruction_total"));
    }
}

// Since SPIR-V 1.4 an entry point lists every global variable it uses.
void list_in_entry_points(Module& m, const Counter& c) {
    if (m.header[1] < 0x00010400u) return;
    for (Inst& in : m.insts)
        if (opcode(in) == spv::OpEntryPoint) {
            in.push_back(c.counter);
            in.push_back(c.buffer);
            in[0] = uint32_t(in.size()) << 16 | spv::OpEntryPoint;
        }
}

// Block `b` of a function (an entry point's when `entry`) into `body`, from the instruction
// `copied` on: its static count added to the counter, and the counter added to the buffer where
// an invocation ends. Returns the first instruction not yet copied.
size_t instrument_block(const std::vector<Inst>& insts, const Block& b, bool entry, size_t copied, Counter& c,
                        std::vector<Inst>& body) {
    // OpPhi must open a block and OpVariable the function's first one: count after them.
    size_t at = b.begin + 1;
    while (at < b.end && (opcode(insts[at]) == spv::OpPhi || is_debug_line(opcode(insts[at])) ||
                          (b.first && opcode(insts[at]) == spv::OpVariable)))
        ++at;
    for (; copied < at; ++copied) body.push_back(insts[copied]);
    uint32_t n = static_count(insts, b);
    uint32_t loaded = c.fresh(), sum = c.fresh();
    body.push_back(make(spv::OpLoad, {c.u64, loaded, c.counter}));
    body.push_back(make(spv::OpIAdd, {c.u64, sum, loaded, c.constant(n)}));
    body.push_back(make(spv::OpStore, {c.counter, sum}));
    size_t terminator = b.end - 1;
    spv::Op term = opcode(insts[terminator]);
    // An invocation ends at a return of its entry point, or wherever a fragment is
    // discarded (OpKill, OpTerminateInvocation: in any function).
    if ((entry && term == spv::OpReturn) || term == spv::OpKill || term == spv::OpTerminateInvocation) {
        for (; copied < terminator; ++copied) body.push_back(insts[copied]);
        uint32_t total = c.fresh(), ptr = c.fresh(), old = c.fresh();
        body.push_back(make(spv::OpLoad, {c.u64, total, c.counter}));
        body.push_back(make(spv::OpAccessChain, {c.ptr_sb_u64, ptr, c.buffer, c.index0}));
        body.push_back(make(spv::OpAtomicIAdd, {c.u64, old, ptr, c.scope_device, c.relaxed, total}));
    }
    return copied;
}

// The function bodies, rewritten block by block.
std::vector<Inst> instrument_functions(const Module& m, const Survey& s, Counter& c) {
    std::vector<Inst> body;
    for (size_t i = s.first_function; i < m.insts.size(); ++i) {
        if (opcode(m.insts[i]) != spv::OpFunction)
            throw Error("SPIR-V instrumentation: unexpected instruction between functions");
        bool entry = s.entry_functions.count(m.insts[i][2]) > 0;
        size_t end = i;
        std::vector<Block> blocks = blocks_of_function(m.insts, i, end);
        size_t copied = i;
        for (const Block& b : blocks) copied = instrument_block(m.insts, b, entry, copied, c, body);
        for (; copied <= end; ++copied) body.push_back(m.insts[copied]);
        i = end;
    }
    return body;
}

// The module's preamble and globals with the additions in their places, then the new bodies.
std::vector<uint32_t> assemble(const Module& m, const Survey& s, const Counter& c, const std::vector<Inst>& body) {
    std::vector<uint32_t> out = m.header;
    out[3] = c.bound;
    auto emit = [&](const std::vector<Inst>& v) {
        for (const Inst& in : v) out.insert(out.end(), in.begin(), in.end());
    };
    for (size_t i = 0; i < s.first_function; ++i) {
        if (i == s.first_global) emit(c.decorations_add);
        out.insert(out.end(), m.insts[i].begin(), m.insts[i].end());
        if (i == s.last_cap) emit(c.caps_add);
        if (i == s.last_name && s.last_name) emit(c.names_add);
    }
    if (s.first_global == s.first_function) emit(c.decorations_add);
    emit(c.globals_add);
    emit(body);
    return out;
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
    const Survey s = survey(m);
    Counter c(m.header[3]);
    declare_missing_types(s, c);
    declare_counter(s, c);
    list_in_entry_points(m, c);
    std::vector<Inst> body = instrument_functions(m, s, c);
    return assemble(m, s, c, body);
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
