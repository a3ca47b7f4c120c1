# The folders a test program makes with testutil::temp_dir (test_support.h) are gone when it exits
# after its tests passed, and stay, named on stderr, when one failed.
#   cmake -DPROBE=<temp_dirs_probe> -DWORK=<empty folder> -P check_temp_dirs.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}/pass" "${WORK}/fail")

execute_process(COMMAND ${CMAKE_COMMAND} -E env TMPDIR=${WORK}/pass ${PROBE} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the probe failed (${rc}):\n${out}${err}")
endif()
file(GLOB left "${WORK}/pass/*")
if(left)
  message(FATAL_ERROR "after its tests passed, the probe left ${left}")
endif()

execute_process(COMMAND ${CMAKE_COMMAND} -E env TMPDIR=${WORK}/fail IBLCHECK_PROBE_FAIL=1 ${PROBE}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "the probe passed with IBLCHECK_PROBE_FAIL set:\n${out}")
endif()
file(GLOB kept "${WORK}/fail/iblcheck_probe_*/left.txt")
if(NOT kept)
  message(FATAL_ERROR "after a failed test, the probe's folder is gone (it should stay for a look)")
endif()
if(NOT err MATCHES "a test failed: its files stay in [^\n]*iblcheck_probe_")
  message(FATAL_ERROR "after a failed test, stderr does not say where the files are:\n${err}")
endif()
file(REMOVE_RECURSE "${WORK}")
message(STATUS "passing run: nothing left; failing run: the folder kept and named")
