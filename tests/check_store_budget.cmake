# Issue 33: the stores stay within their budget (kernel/store_budget.h). The iblcheck binary end to
# end, in a cache folder of its own:
#   1. with the default budget a render keeps an old entry;
#   2. with IBLCHECK_CACHE_MAX_MB=1 a render that writes removes the old entries (the one planted and
#      the first render's, both made old), keeps its own (over the budget on their own) and never
#      touches what is not an entry (a writer's temporary file, a note);
#   3. a bad budget is refused before any work: exit 2, and 125 for bisect.
#   cmake -DIBLCHECK=iblcheck -DOUT=dir -P check_store_budget.cmake
file(REMOVE_RECURSE "${OUT}")
set(cache "${OUT}/cache")
file(MAKE_DIRECTORY "${cache}/precompute")
string(REPEAT "0123456789abcdef" 131072 two_mib) # 2 MiB
file(WRITE "${cache}/precompute/00aa.ibl" "${two_mib}")
file(WRITE "${cache}/precompute/00bb.ibl.tmp1-2.ibl" "${two_mib}")
file(WRITE "${cache}/precompute/notes.txt" "not an entry")
execute_process(COMMAND touch -d "2026-01-01 00:00" "${cache}/precompute/00aa.ibl" "${cache}/precompute/00bb.ibl.tmp1-2.ibl"
                "${cache}/precompute/notes.txt")

function(render env budget)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env IBLCHECK_CACHE_DIR=${cache} IBLCHECK_CACHE_MAX_MB=${budget}
                          "${IBLCHECK}" render --scene sphere --method mobile --env ${env} --out "${OUT}/${env}.exr"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "render --env ${env} with IBLCHECK_CACHE_MAX_MB=${budget} exited ${rc}:\n${out}${err}")
  endif()
endfunction()

render(studio "")
if(NOT EXISTS "${cache}/precompute/00aa.ibl")
  message(FATAL_ERROR "the default budget removed an entry although the stores are a few MiB")
endif()
file(GLOB first "${cache}/precompute/*.ibl")
list(FILTER first EXCLUDE REGEX "/00(aa|bb)[^/]*$")
list(LENGTH first n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "the first render stored ${n} precomputes, not 1: ${first}")
endif()
execute_process(COMMAND touch -d "2026-06-01 00:00" ${first})

render(sky_sun 1)
file(GLOB left RELATIVE "${cache}/precompute" "${cache}/precompute/*")
if(EXISTS "${cache}/precompute/00aa.ibl")
  message(FATAL_ERROR "over the budget, the least recently used 00aa.ibl stayed: ${left}")
endif()
if(EXISTS "${first}")
  message(FATAL_ERROR "over the budget, the first render's unused precompute stayed: ${left}")
endif()
foreach(kept 00bb.ibl.tmp1-2.ibl notes.txt)
  if(NOT EXISTS "${cache}/precompute/${kept}")
    message(FATAL_ERROR "pruning removed ${kept}, which is not a store entry: ${left}")
  endif()
endforeach()
list(FILTER left INCLUDE REGEX "^[0-9a-f]+\\.ibl$")
list(LENGTH left own)
if(NOT own EQUAL 1)
  message(FATAL_ERROR "the render's own precompute (over the 1 MiB budget alone) was not kept: ${left}")
endif()

foreach(cmd doctor bisect)
  set(args ${cmd})
  if(cmd STREQUAL bisect)
    set(args bisect --filter "*")
    set(want 125)
  else()
    set(want 2)
  endif()
  execute_process(COMMAND ${CMAKE_COMMAND} -E env IBLCHECK_CACHE_DIR=${cache} IBLCHECK_CACHE_MAX_MB=1.5 "${IBLCHECK}" ${args}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL want OR NOT err MATCHES "IBLCHECK_CACHE_MAX_MB='1\\.5': the stores' size budget must be a whole number")
    message(FATAL_ERROR "${cmd} with IBLCHECK_CACHE_MAX_MB=1.5 exited ${rc} (want ${want}):\n${out}${err}")
  endif()
endforeach()
message("1 MiB budget: the old entries went, the render's own ${left} stayed")
