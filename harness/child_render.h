// Renders in a child process. A render that needs its own environment (LP_NUM_THREADS for the
// thread-count check, GALLIUM_OVERRIDE_CPU_CAPS for the cross-CPU noise floor) cannot set it in
// this process: glibc's setenv is not thread-safe and the runner's workers read the environment
// (getenv in Mesa and in our code) while it would change, and lavapipe reads both variables once
// per driver instance. So such a render runs `iblcheck render` with the variables in its own
// environment block.
#pragma once
#include <filesystem>
#include <map>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "renderers/render_api.h"

namespace iblcheck {

struct ChildRender {
    cv::Mat image;             // CV_32FC3 linear, as the child wrote it (float EXR: exact)
    nlohmann::json provenance; // the child's render provenance (`iblcheck render --json`)
};

// The iblcheck executable: this process if it is iblcheck, else the one built beside the tests.
std::filesystem::path iblcheck_executable();

// Renders `spec` with `iblcheck render` in a child whose environment is this one plus `env`.
// Throws EnvironmentError (no executable) or Error (the child failed: its exit code and the last
// lines of its output).
ChildRender render_in_child(const TestSpec& spec, const std::map<std::string, std::string>& env, const std::string& device = "");

} // namespace iblcheck
