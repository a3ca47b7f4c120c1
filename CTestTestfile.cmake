# `ctest` from the repository root runs the tests built in build/ (README's build folder), so
# `ctest -L ci-suite` works from either folder. Without a build this is an error, not "No tests
# were found" with exit 0.
if(EXISTS "build/CTestTestfile.cmake")
  subdirs("build")
else()
  message(FATAL_ERROR "build/: no build here; run scripts/build.sh (or scripts/test.sh) first")
endif()
