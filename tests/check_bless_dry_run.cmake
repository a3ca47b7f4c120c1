# Issue 30: the committed ci baselines are what `iblcheck bless` writes today (their accuracy and
# cost were stale after the truth was regenerated and the shaders changed, with nothing saying so).
# Runs
#   iblcheck bless --suite ci --dry-run --goldens COPY
# on a copy of goldens/ (a dry run writes nothing; the copy keeps the tree out of reach anyway) and
# fails, listing each baseline that would change, when bless would change anything. Bit-identical
# renders need the CPU class the baselines were blessed on: elsewhere (doctor says the class differs)
# the test is skipped, not passed.
#   cmake -DIBLCHECK=path/to/iblcheck -DSRC=source -DOUT=dir -P check_bless_dry_run.cmake
file(REMOVE_RECURSE "${OUT}")
file(COPY "${SRC}/goldens/" DESTINATION "${OUT}")
execute_process(COMMAND "${CMAKE_COMMAND}" -E env "IBLCHECK_GOLDEN_DIR=${OUT}" "${IBLCHECK}" doctor OUTPUT_VARIABLE doctor
                ERROR_VARIABLE doctor RESULT_VARIABLE rc)
if(NOT doctor MATCHES "primary[^\n]*matches this machine")
  message("SKIPPED: the ci baselines were blessed on another CPU class; renders here are not bit-identical:\n${doctor}")
  return()
endif()
execute_process(COMMAND "${IBLCHECK}" bless --suite ci --dry-run --goldens "${OUT}" OUTPUT_VARIABLE out ERROR_VARIABLE err
                RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "iblcheck bless --suite ci --dry-run exited ${rc}: the committed baselines are stale (the "
                      "\"would\" lines); look at the changes, then run build/iblcheck bless --suite ci\n${out}\n${err}")
endif()
