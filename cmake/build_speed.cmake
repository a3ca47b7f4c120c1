# Build speed (issue 20): a fresh build on 2 cores in under 2 minutes. Nothing here changes what
# is built, only how fast:
#   - ccache when installed (optional; IBLCHECK_CCACHE=OFF to skip it),
#   - one precompiled header for the test programs (tests/CMakeLists.txt, IBLCHECK_TEST_PCH),
#   - scripts/build.sh builds only the tool; the test programs are built by test.sh (build.sh --all),
#   - lld, else gold, instead of ld.bfd (a link of iblcheck: 1.8 s CPU with bfd, 1.1 gold, 0.5 lld),
#   - unity builds: the .cpp files of a target compiled as one translation unit, so nlohmann/json,
#     fmt, CLI11 and OpenCV templates are parsed, instantiated and optimised once per target instead
#     of once per file (IBLCHECK_UNITY=OFF for one file per translation unit). Batches of 8 files
#     (stops 20-36) against one batch per target, cold, 2 cores (stop 37): the report library 69.6
#     against 39.0 s of CPU, the harness 59.1 against 32.1 s, the whole build 668 against 564 s.
#     A target's files keep their file-local helpers apart by name (tests: a namespace per file).
#   - static libraries compile without waiting for the libraries they link (they only need them
#     at the final link), so both cores have work from the start.
option(IBLCHECK_CCACHE "Use ccache when it is installed" ON)
option(IBLCHECK_UNITY "Unity builds (fewer, larger translation units)" ON)
set(IBLCHECK_LINKER "auto" CACHE STRING "Linker: auto (lld, else gold, else the default), lld, gold, bfd or default")

if(IBLCHECK_CCACHE)
  find_program(IBLCHECK_CCACHE_PROGRAM ccache)
  if(IBLCHECK_CCACHE_PROGRAM)
    # The tests' precompiled header (tests/CMakeLists.txt) is cacheable only with these sloppiness
    # settings (ccache manual, "Precompiled headers"); without them ccache compiles those uncached.
    set(CMAKE_CXX_COMPILER_LAUNCHER env CCACHE_SLOPPINESS=pch_defines,time_macros "${IBLCHECK_CCACHE_PROGRAM}")
    message(STATUS "iblcheck: compiling through ${IBLCHECK_CCACHE_PROGRAM}")
  endif()
endif()

include(CheckLinkerFlag)
set(_linker "")
if(IBLCHECK_LINKER STREQUAL "auto")
  foreach(candidate lld gold)
    check_linker_flag(CXX "-fuse-ld=${candidate}" IBLCHECK_HAS_LD_${candidate})
    if(IBLCHECK_HAS_LD_${candidate})
      set(_linker ${candidate})
      break()
    endif()
  endforeach()
elseif(NOT IBLCHECK_LINKER STREQUAL "default")
  set(_linker ${IBLCHECK_LINKER})
endif()
if(_linker)
  add_link_options(-fuse-ld=${_linker})
  message(STATUS "iblcheck: linking with ${_linker}")
endif()

if(IBLCHECK_UNITY)
  set(CMAKE_UNITY_BUILD ON)
  set(CMAKE_UNITY_BUILD_BATCH_SIZE 0) # one unit per target
endif()
set(CMAKE_OPTIMIZE_DEPENDENCIES ON)
