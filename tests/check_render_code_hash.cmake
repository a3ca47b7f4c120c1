# Issue 33: the precompute and cost stores key on the renderer code's hash (kernel/program.h:
# render_code_hash), which cmake/render_code_hash.cmake takes of the renderer libraries at build time.
# Checks that the hash is the same for the same files, differs when one byte of one file changes,
# refuses a missing file, and that the iblcheck binary's stores use the hash its build generated.
#   cmake -DIBLCHECK=iblcheck -DSCRIPT=cmake/render_code_hash.cmake -DGENERATED=build/cli/render_code_hash.cpp
#         -DOUT=dir -P check_render_code_hash.cmake
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}")
file(WRITE "${OUT}/a.a" "the first library's bytes")
file(WRITE "${OUT}/b.a" "the second library's bytes")
function(hash_of files result)
  execute_process(COMMAND "${CMAKE_COMMAND}" "-DFILES=${files}" "-DOUT=${OUT}/hash.cpp" -P "${SCRIPT}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    set(${result} "failed: ${err}" PARENT_SCOPE)
    return()
  endif()
  file(READ "${OUT}/hash.cpp" text)
  string(REGEX MATCH "return \"([0-9a-f]+)\"" _ "${text}")
  set(${result} "${CMAKE_MATCH_1}" PARENT_SCOPE)
endfunction()
hash_of("${OUT}/a.a|${OUT}/b.a" first)
hash_of("${OUT}/a.a|${OUT}/b.a" again)
file(WRITE "${OUT}/b.a" "the second library's bytez")
hash_of("${OUT}/a.a|${OUT}/b.a" changed)
hash_of("${OUT}/a.a|${OUT}/missing.a" missing)
if(NOT first MATCHES "^[0-9a-f]+$" OR NOT first STREQUAL again)
  message(FATAL_ERROR "the same files gave '${first}' and then '${again}'")
endif()
if(changed STREQUAL first)
  message(FATAL_ERROR "a changed byte kept the hash ${first}")
endif()
if(NOT missing MATCHES "^failed: .*missing\\.a")
  message(FATAL_ERROR "a missing library was not refused: '${missing}'")
endif()
# The binary: `doctor` names the key its stores use, which is the hash its build generated.
file(READ "${GENERATED}" generated)
string(REGEX MATCH "return \"([0-9a-f]+)\"" _ "${generated}")
set(built "${CMAKE_MATCH_1}")
execute_process(COMMAND "${IBLCHECK}" doctor OUTPUT_VARIABLE doctor ERROR_VARIABLE doctor_err RESULT_VARIABLE rc)
if(NOT doctor MATCHES "store code key: +render-code:${built}\n")
  message(FATAL_ERROR "iblcheck doctor does not give the generated render code hash ${built}:\n${doctor}${doctor_err}")
endif()
message("render code hash: ${first} -> ${changed} after one byte; the binary's stores use ${built}")
