// The iblcheck binary as the commands it prints name it (bless, truth): they must run when pasted.
// `iblcheck bless ...` was "command not found" after scripts/run.sh, which builds build/iblcheck and
// puts nothing on PATH. The CLI sets the name from the binary that is running (program_from_self);
// a library user (the test programs, run in-process) keeps "iblcheck".
#pragma once
#include <string>

namespace iblcheck {

// "iblcheck" until set_program_name; the first word of every printed iblcheck command.
const std::string& program_name();
void set_program_name(const std::string& name);

// The running binary (/proc/self/exe) as a person types it: "iblcheck" when that name on PATH is this
// binary; else its path relative to the current folder when that is shorter than the absolute path
// ("build/iblcheck", "./iblcheck"), else the absolute path; shell-quoted when it needs it.
std::string program_from_self();

// The content hash (FNV-1a 64, hex) of the file at `path`; empty when it cannot be read.
std::string file_content_hash(const std::string& path);

// The running binary's content hash (/proc/self/exe), computed once: the stores' key part for the
// tool's own C++ where the binary has no render_code_hash or metrics_code_hash (the test programs).
// Without it an entry made by another build of the tool was read back: a bisect across a C++
// change, whose steps share .cache/, judged each commit with the first one's precompute. A
// shader-only change relinks nothing and keeps the hash (shaders are keyed by content on their
// own). "unreadable" when /proc/self/exe cannot be read (every build then shares it).
const std::string& running_binary_hash();

// The part of the precompute and cost stores' keys that stands for the C++ computing what they hold:
// the renderer libraries, the glslang/SPIRV-Tools archives and libastcenc, hashed when the iblcheck
// binary is built (cmake/render_code_hash.cmake). A change to the harness, the report or the CLI
// keeps it, so a nightly or a bisect step after such a change reads the entries an earlier build
// made; a change to a renderer library (or to one of those libraries) is a miss. A binary built
// without it (the test programs) uses running_binary_hash(), as every store did before (issue 33).
const std::string& render_code_hash();

// The metrics store's counterpart (harness/metrics_store.h): the metric code, hashed when the
// iblcheck binary is built from the metrics, metric catalog, metrics store, image and kernel
// libraries and the OpenCV libraries SSIM and the display transform call (cmake/render_code_hash.cmake
// with NAME=metrics). A change to the renderers, the rest of the harness, the report or the CLI
// keeps it; running_binary_hash() in a binary built without it.
const std::string& metrics_code_hash();

} // namespace iblcheck
