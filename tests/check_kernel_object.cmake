# The AVX2 build of FLIP's kernels (metrics/flip/kernels_avx2.cpp) must define no external symbol
# but its accessor: an inline helper or template instantiated there with AVX2 instructions could be
# the copy the linker keeps for every caller, and crash a CPU without AVX2 (or change its results).
#   cmake -DNM=<nm> -DOBJECTS=<object files> -P check_kernel_object.cmake
foreach(obj IN LISTS OBJECTS)
  execute_process(COMMAND "${NM}" --defined-only --extern-only "${obj}" OUTPUT_VARIABLE syms RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${NM} failed on ${obj}")
  endif()
  string(REGEX REPLACE "\n$" "" syms "${syms}")
  string(REPLACE "\n" ";" lines "${syms}")
  set(found_accessor FALSE)
  foreach(line IN LISTS lines)
    if(line MATCHES "_ZN8iblcheck4flip12avx2_kernelsEv$")
      set(found_accessor TRUE)
    elseif(NOT line STREQUAL "")
      message(FATAL_ERROR "${obj} exports a symbol besides avx2_kernels(): ${line}")
    endif()
  endforeach()
  if(NOT found_accessor)
    message(FATAL_ERROR "${obj}: no avx2_kernels() (checked the wrong object?)")
  endif()
  message(STATUS "${obj}: only avx2_kernels() is external")
endforeach()
