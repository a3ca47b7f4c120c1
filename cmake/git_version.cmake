# Writes OUT (build/iblcheck_commit.txt, beside the binary) with the checkout's commit, run at every
# build by the iblcheck_git_version target (harness/CMakeLists.txt). `iblcheck --version` reads it at
# run time: compiled in, a new commit or a shader edit (which makes the tree dirty) recompiled
# version.cpp and relinked the tool, so every bisect step relinked (issue 33).
#   cmake -DSRC=<source dir> -DOUT=<file> -P this
set(commit "unknown")
find_package(Git QUIET)
if(GIT_FOUND)
  execute_process(COMMAND "${GIT_EXECUTABLE}" -C "${SRC}" rev-parse --short=12 HEAD
                  OUTPUT_VARIABLE head RESULT_VARIABLE rc OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(rc EQUAL 0 AND NOT head STREQUAL "")
    set(commit "${head}")
    execute_process(COMMAND "${GIT_EXECUTABLE}" -C "${SRC}" status --porcelain --untracked-files=no
                    OUTPUT_VARIABLE changes RESULT_VARIABLE rc2 ERROR_QUIET)
    if(rc2 EQUAL 0 AND NOT changes STREQUAL "")
      set(commit "${commit}-dirty")
    endif()
  endif()
endif()
file(WRITE "${OUT}.tmp" "${commit}\n")
file(COPY_FILE "${OUT}.tmp" "${OUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUT}.tmp")
