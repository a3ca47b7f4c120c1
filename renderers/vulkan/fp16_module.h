// The fp16 emulation pass's bookkeeping, internal to renderers/vulkan (fp16_emulation.cpp holds the
// rewriting of function bodies and says what the pass does and why):
//   * the module as a list of instructions (parse) and back to words (assemble_widened);
//   * what its types say about 16-bit floats (TypeTable), and the refusals for what cannot be
//     widened without changing meaning;
//   * the ids, types and constants the rewriting adds (Declarations);
//   * the last step: OpTypeFloat 16 becomes 32 and the types that then duplicate others merge.
#pragma once
#include <glslang/SPIRV/spirv.hpp>

#include <cstdint>
#include <map>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

namespace iblcheck::vk::fp16 {

struct Inst {
    std::vector<uint32_t> words;
    std::vector<uint16_t> id_slots; // word indices of id operands, the result type's included, the result id's not
    spv::Op op() const { return spv::Op(words[0] & 0xffff); }
    uint32_t result = 0, type = 0;
    bool glsl_ext = false; // OpExtInst of GLSL.std.450
};

// An instruction from its operands (result type and id included, where it has them).
Inst make(spv::Op op, std::vector<uint32_t> operands, std::vector<uint16_t> id_slots, uint32_t type, uint32_t result);

struct Module {
    std::vector<uint32_t> header; // magic, version, generator, bound, schema
    std::vector<Inst> insts;
};

// Throws ShaderCompileError when `spirv` does not parse.
Module parse(const std::vector<uint32_t>& spirv);

// The fp32 bit pattern of an fp16 one (exact; subnormals become normal fp32 values).
uint32_t half_bits_to_float_bits(uint32_t h);

struct TypeInfo {
    spv::Op op;
    uint32_t width = 0;     // OpTypeFloat, OpTypeInt
    uint32_t component = 0; // OpTypeVector/Matrix: component/column type; OpTypeInt: signedness
    uint32_t count = 0;     // OpTypeVector: components
};

// The 16-bit float, the values built on it, and everything that contains it.
struct TypeTable {
    std::unordered_map<uint32_t, TypeInfo> types;
    std::set<uint32_t> halfish;     // types that contain a 16-bit float anywhere
    std::set<uint32_t> half_values; // the fp16 scalar and vector types: results that get rounded
    uint32_t half = 0, glsl_set = 0;
    std::unordered_map<uint32_t, uint32_t> value_type; // result id → its type

    uint32_t type_of(uint32_t id) const;      // 0 for an id without a type
    uint32_t count_of(uint32_t type) const;   // a vector's components (0 for a scalar or an unknown id)
    uint32_t components(uint32_t type) const; // of an fp16 value type: 1 for the scalar, else count_of
    bool is_f32_value(uint32_t type) const;   // a 32-bit float scalar or vector
};

// Reads the module's types. Throws ShaderCompileError for 16-bit float matrices, images and
// pointers outside Function/Private/Workgroup storage (their layout would change).
TypeTable scan_types(const Module& m);

// Throws ShaderCompileError for instructions whose meaning widening would change: 16-bit float
// controls, bit casts of 16-bit floats, 16-bit float specialization constants.
void reject_unwidenable_uses(const Module& m, const TypeTable& t);

// The fresh ids, and the uint/bool types and constants the rounding needs: found among the
// module's declarations or appended to globals().
class Declarations {
  public:
    Declarations(const TypeTable& t, uint32_t bound);
    uint32_t fresh() { return bound_++; }
    uint32_t bound() const { return bound_; }
    // The id of the type `op operands`: an existing declaration, else a new one.
    uint32_t type_decl(spv::Op op, std::vector<uint32_t> operands, std::vector<uint16_t> slots);
    // A constant of `type` (scalar, or vector of `n` `scalar`s) with every component `bits`.
    uint32_t constant(uint32_t type, uint32_t scalar, uint32_t n, uint32_t bits);
    std::vector<Inst>& globals() { return globals_; }

  private:
    uint32_t scalar_constant(uint32_t type, uint32_t bits);
    uint32_t bound_;
    std::vector<Inst> globals_;
    std::map<std::vector<uint32_t>, uint32_t> declared_;          // opcode + operands → id, for types
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> constants_; // (type, bits) → id
};

// The rewritten module as words: every 16-bit float type becomes 32-bit, the types that then equal
// an earlier one are merged into it (with their names and decorations), NoContraction decorations
// follow `renamed` (original id → the fresh id of the unrounded arithmetic), and the header's
// bound becomes `bound`.
std::vector<uint32_t> assemble_widened(std::vector<Inst>& insts, const std::vector<uint32_t>& header, uint32_t bound,
                                       const std::set<uint32_t>& halfish, const std::unordered_map<uint32_t, uint32_t>& renamed);

} // namespace iblcheck::vk::fp16
