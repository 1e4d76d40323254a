# Sourced by the build scripts (scripts/build.sh, scripts/run_tests_novtk.sh): ccache as the
# compiler launcher when it is installed (scripts/setup.sh installs it), with the clone as its
# base directory, so that paths under it are hashed relative to the build directory. The plain
# build (./build) and CI's sanitized build (./build-novtk-sanitize) sit at the same depth and
# compile the tests' own code with the same command (CMakeLists.txt, jointid_test_code): the
# second build takes those objects from the cache instead of compiling them again
# (docs/errors.md, "Sanitizers"). Paths in compiler messages and in __FILE__ are then relative
# to the build directory.
cache_cmake_args=()
if command -v ccache >/dev/null 2>&1; then
  export CCACHE_BASEDIR="${root:-$(pwd)}"
  cache_cmake_args=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
