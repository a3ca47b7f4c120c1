# The reference regeneration script names its goldens as the binary does (it asks `iblcheck truth
# --print-name`, the golden store's reference_key; it used to spell the rule again in bash) and writes
# exactly the reference goldens there are: its listing (LIST=1 TEMPORAL=1, nothing rendered) equals the
# names of goldens/reference/*.exr, the files the suites read.
#   cmake -DIBLCHECK=<binary> -DSRC=<repository root> -P check_golden_names.cmake
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env LIST=1 TEMPORAL=1 IBLCHECK=${IBLCHECK} bash ${SRC}/scripts/regenerate_reference_goldens.sh
  OUTPUT_VARIABLE listed ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "LIST=1 scripts/regenerate_reference_goldens.sh failed (${rc}):\n${listed}${err}")
endif()
string(REGEX MATCHALL "[^\n]+" listed "${listed}")  # one name a line
list(SORT listed)
file(GLOB goldens RELATIVE ${SRC}/goldens/reference ${SRC}/goldens/reference/*.exr)
list(TRANSFORM goldens REPLACE "\\.exr$" "")
list(SORT goldens)
list(LENGTH goldens n)
if(n EQUAL 0)
  message(FATAL_ERROR "no goldens in ${SRC}/goldens/reference: wrong SRC?")
endif()
if(NOT listed STREQUAL goldens)
  set(only_script ${listed})
  list(REMOVE_ITEM only_script ${goldens})
  set(only_store ${goldens})
  list(REMOVE_ITEM only_store ${listed})
  message(FATAL_ERROR "the script's golden names differ from goldens/reference/:\n  named by the script only: "
                      "${only_script}\n  in goldens/reference/ only: ${only_store}")
endif()
message(STATUS "${n} reference goldens, named alike by the script and the binary")
