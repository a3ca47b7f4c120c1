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

} // namespace iblcheck
