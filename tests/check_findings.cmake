# The check scripts' ending (cmake -P): every finding on a line of its own under `title` and a fatal
# error, or, with none, the summary of what was checked.
function(report_findings title summary)
  if(ARGN)
    list(JOIN ARGN "\n  " lines)
    message(FATAL_ERROR "${title}:\n  ${lines}")
  endif()
  message(STATUS "${summary}")
endfunction()
