#pragma once
// Function multiversioning that sanitizer builds can start.
//
// GCC's target_clones makes an ifunc whose resolver the dynamic loader runs while it relocates the
// program, before the TSan/ASan runtime is set up; an instrumented resolver then crashes the
// program at start-up (SIGSEGV before main, seen in CI's TSan step). Sanitizer builds therefore
// get the default version only; normal builds get an AVX2+FMA clone picked at run time.
// Use IBLCHECK_CLONES_HASWELL instead of writing target_clones by hand: tests/check_no_raw_clones.cmake
// fails the build's tests on any raw use.
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
#define IBLCHECK_CLONES_HASWELL
#else
#define IBLCHECK_CLONES_HASWELL __attribute__((target_clones("arch=haswell", "default")))
#endif
