# Sourced by the scripts that configure a build folder (build.sh, sanitize.sh, bisect_step.sh,
# regenerate_reference_goldens.sh): Ninja as the generator when it is installed
# (scripts/setup.sh installs ninja-build beside ccache and lld; the build works without it).
# Measured on 2 cores (issue 33): sanitize.sh's ASan build of four test programs, one
# `cmake --build --target a b c d`, took 134 s with Make, which builds the goals one after another
# (CMake's top Makefile is .NOTPARALLEL), and 102 s with Ninja; a build with nothing to do takes
# 2.6 s with Make and 0.1 s with Ninja (every bisect step and every run of the README's commands).
# CMake reads CMAKE_GENERATOR only for a folder it has not configured yet, so a build folder made
# with Make stays Make; an explicit CMAKE_GENERATOR in the environment wins.
if [[ -z "${CMAKE_GENERATOR:-}" ]] && command -v ninja >/dev/null 2>&1; then
  export CMAKE_GENERATOR=Ninja
fi
