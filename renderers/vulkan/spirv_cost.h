// A deterministic execution cost for compute shaders (issue 14): the number of SPIR-V
// instructions each invocation executes, counted by the shader itself.
//
// Wall and timestamp times on a shared CPU vary 2-5x between identical runs, and lavapipe offers no
// hardware counters, so a cost gate needs a figure that depends on the SPIR-V and the data only.
// instrument_instruction_count() rewrites a module so that every basic block of every function adds
// its static instruction count to a per-invocation counter, and every return of an entry point (and
// every fragment discard, OpKill/OpTerminateInvocation) adds that counter to a buffer at (set 0,
// binding kCostBinding). Any stage: a graphics pipeline binds the buffer to its vertex and fragment
// stages (graphics_pipeline.h). Helper invocations (the fragment quads' pixels outside the
// primitive) execute but cannot write memory, so their instructions are not counted. The count is what the SPIR-V says is
// executed, so it is the same on every CPU class, thread count and driver that takes the same
// branches; it says nothing about what the driver's compiler makes of it. It counts what ran: on
// lavapipe an invocation's loops end once it has made 65535 trips in all (gallivm's loop
// limiter), so a runaway loop's count, like its time, stops growing there.
#pragma once
#include <cstdint>
#include <vector>

#include "context.h"

namespace iblcheck::vk {

// Descriptor set 0 binding of the counter buffer (a single uint64): the shaders use 0..5.
inline constexpr uint32_t kCostBinding = 15;
// Part of the SPIR-V cache key of instrumented shaders: bump it when the pass's output changes.
inline constexpr int kCostPassVersion = 2; // 2: counted before the fp16 emulation

// A block's static instruction count: every instruction from the one after its OpLabel to its
// terminator, both included, except OpLine/OpNoLine (debug annotations). OpPhi, OpVariable and
// the merge declarations count; the OpLabel does not. The instrumentation adds none of its own.
//
// Overflow: the per-invocation counter is a Private uint64 and the total a uint64 updated with
// OpAtomicIAdd (the Int64 and Int64Atomics capabilities: device features shaderInt64 and
// shaderBufferInt64Atomics, which lavapipe has). 32 bits would not do: shade_spheres runs ~6.3e3
// instructions a pixel at ssaa 2, so a 200x slower shader on a 1920x1080 frame executes ~2.6e12 in
// one dispatch (2^32 is 4.3e9; 2^64 leaves 10^7 of headroom). One invocation of it runs ~1.3e6,
// but a runaway loop can pass 2^32 on a driver without lavapipe's 65535-trip loop limiter, and a
// 64-bit add costs what a 32-bit one does. One atomic per invocation (at its returns) keeps the
// contention low; integer sums are exact in any order, so the total is deterministic.
//
// Throws ShaderCompileError when the module already uses set 0 binding kCostBinding, Error when
// it is not SPIR-V 1.3 or later (the StorageBuffer storage class) or is malformed.
std::vector<uint32_t> instrument_instruction_count(const std::vector<uint32_t>& spirv);

// The static instruction count of each block of each function, in module order (blocks in the
// order they appear): what the instrumentation adds per block. For tests and reports.
std::vector<std::vector<uint32_t>> block_instruction_counts(const std::vector<uint32_t>& spirv);

// Records nothing timed: dispatches `counted` (a pipeline compiled with count_instructions) once
// with `bindings` plus a fresh counter buffer at kCostBinding, waits, and returns the SPIR-V
// instructions the dispatch executed, summed over every invocation.
uint64_t count_dispatch_instructions(Context& ctx, const ComputePipeline& counted, std::vector<Binding> bindings,
                                     const void* push, uint32_t push_bytes, uint32_t gx, uint32_t gy = 1, uint32_t gz = 1);

} // namespace iblcheck::vk
