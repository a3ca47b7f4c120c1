# Every function multiversioning goes through IBLCHECK_CLONES_HASWELL (kernel/multiversion.h),
# which sanitizer builds turn off: a raw target_clones makes an ifunc resolver that crashes a TSan or
# ASan build before main (scripts/sanitize.sh, run by CI, then fails with SIGSEGV and no message).
#   cmake -DSOURCE_DIR=<repository root> -P check_no_raw_clones.cmake
file(GLOB_RECURSE sources RELATIVE "${SOURCE_DIR}"
     "${SOURCE_DIR}/harness/*.cpp" "${SOURCE_DIR}/harness/*.h" "${SOURCE_DIR}/metrics/*.cpp" "${SOURCE_DIR}/metrics/*.h"
     "${SOURCE_DIR}/metrics/*.inc" "${SOURCE_DIR}/renderers/*.cpp" "${SOURCE_DIR}/renderers/*.h"
     "${SOURCE_DIR}/tests/*.cpp" "${SOURCE_DIR}/tests/*.h" "${SOURCE_DIR}/kernel/*.cpp" "${SOURCE_DIR}/kernel/*.h"
     "${SOURCE_DIR}/image_io/*.cpp" "${SOURCE_DIR}/image_io/*.h" "${SOURCE_DIR}/results/*.cpp" "${SOURCE_DIR}/results/*.h"
     "${SOURCE_DIR}/reports/*.cpp" "${SOURCE_DIR}/reports/*.h" "${SOURCE_DIR}/cli/*.cpp" "${SOURCE_DIR}/cli/*.h")
set(bad "")
set(checked 0)
foreach(f IN LISTS sources)
  if(f STREQUAL "kernel/multiversion.h")
    continue()
  endif()
  math(EXPR checked "${checked} + 1")
  file(STRINGS "${SOURCE_DIR}/${f}" hits REGEX "__attribute__[ ]*\\(\\([ ]*target")
  if(hits)
    list(APPEND bad "${f}")
  endif()
endforeach()
if(checked LESS 50)
  message(FATAL_ERROR "only ${checked} source files found under ${SOURCE_DIR}: wrong SOURCE_DIR?")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/check_findings.cmake)
report_findings("raw multiversioning (use IBLCHECK_CLONES_HASWELL from kernel/multiversion.h)"
                "${checked} source files: no raw target_clones/target attribute" ${bad})
