// Error types shared by every module. The CLI maps them to exit codes (docs/DESIGN.md, Conventions):
// 0 pass, 1 regression, 2 usage/input/environment error. Messages name the file and the problem.
#pragma once
#include <stdexcept>
#include <string>

namespace iblcheck {

// Exit codes of the whole CLI.
inline constexpr int kExitPass = 0;
inline constexpr int kExitRegression = 1;
inline constexpr int kExitError = 2;        // usage, input or environment error
inline constexpr int kExitCannotTest = 125; // `git bisect run`: skip this commit

struct Error : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// Bad command line or option value (unknown scene, malformed --set).
struct UsageError : Error {
    using Error::Error;
};
// Bad input file or data: missing/corrupt image, size mismatch, NaN/Inf pixels, bad suite file.
struct InputError : Error {
    using Error::Error;
};
// The machine cannot run the job: no Vulkan driver, missing feature.
struct EnvironmentError : Error {
    using Error::Error;
};
// A render completed but its pixels are not finite (NaN/Inf): the shader under test is wrong, so
// this is a regression (verdict fail, exit 1, bisect "bad"), not "cannot test".
struct NonFiniteRender : Error {
    using Error::Error;
};
// A GLSL source failed to compile; the message carries file:line.
struct ShaderCompileError : Error {
    using Error::Error;
};

} // namespace iblcheck
