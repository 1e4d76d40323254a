# Sourced by the scripts that run the suite under AddressSanitizer and UndefinedBehaviorSanitizer
# (scripts/run_tests_novtk.sh --sanitize, scripts/run_sanitized_tests.sh): what the sanitizers
# report and when they stop. Any finding aborts its test. LeakSanitizer's suppressions name only
# system libraries that are not instrumented (scripts/lsan.supp).
root=${root:-$(pwd)}
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# -O2 rather than -O1: Eigen's expression templates are 10-30x slower when not inlined (the
# discovery tests took 150-600 s each at -O1); ASan and UBSan see the same accesses either way.
# Eigen's own index assertions are off (EIGEN_NO_DEBUG): ASan checks the accesses themselves;
# jointid's assertions stay on (-UNDEBUG). -g1: line tables only, all a report's stack trace
# needs. A Release build whose instrumented code takes these flags after the build type's
# (JOINTID_SANITIZE_FLAGS): uninstrumented test code (JOINTID_SANITIZE_TEST_CODE=OFF) then
# compiles exactly as in the plain Release build, and a compiler cache reuses its objects.
sanitize_flags="-O2 -g1 -UNDEBUG -DEIGEN_NO_DEBUG"
sanitize_cmake_args=(-DCMAKE_BUILD_TYPE=Release "-DJOINTID_SANITIZE_FLAGS=$sanitize_flags"
  -DJOINTID_SANITIZE=address,undefined)
