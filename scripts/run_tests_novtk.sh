#!/usr/bin/env bash
# The build without VTK and without the SLEPc engine (what a headless node without PETSc gets):
# configures ./build-novtk with -DJOINTID_WITH_VTK=OFF -DJOINTID_WITH_SLEPC=OFF (no benchmarks),
# builds it and runs its tests: everything but the VTK files and pictures, plus the checks that
# `modes`, `discover` and `--engine slepc` say what this build lacks.
#   --sanitize: the same build under AddressSanitizer (with LeakSanitizer) and
#     UndefinedBehaviorSanitizer, in ./build-novtk-sanitize (scripts/sanitizer_env.sh); any
#     finding fails its test. Left to the uninstrumented builds (docs/errors.md, "Sanitizers"):
#     the two example studies and the Monte Carlo coverage tests (instrumented they run for over
#     16 min each), and eight discovery tests of 74-220 s each instrumented that repeat, with other
#     parameters, paths the other discovery tests run under the sanitizers. This is what CI runs
#     (.ci/run: one build for both checks).
# Other arguments go to cmake.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
build=build-novtk
config=(-DCMAKE_BUILD_TYPE=Release)
exclude=()
if [[ "${1:-}" == "--sanitize" ]]; then
  shift
  # shellcheck source=scripts/sanitizer_env.sh
  source scripts/sanitizer_env.sh # exported for the build too: gtest_discover_tests runs the tests
  build=build-novtk-sanitize
  # jointid's libraries and programs instrumented, the tests' own code not (a third of the
  # compile time); what is left out and why: docs/errors.md, "Sanitizers".
  # UBSan without its null and alignment checks: they instrument every pointer access and
  # double the instrumented compile (identify/fit.cpp, user CPU: 132 s with them, 66 s without,
  # 53 s under ASan alone); a null dereference still faults and ASan reports it with its stack,
  # and x86-64 loads misaligned data (Eigen's own aligned loads fault on it). The full set runs
  # in scripts/run_sanitized_tests.sh.
  config=("${sanitize_cmake_args[@]}" -DJOINTID_SANITIZE_TEST_CODE=OFF
    "-DJOINTID_SANITIZE_FLAGS=$sanitize_flags -fno-sanitize=alignment,null")
  repeats="^Discover/NoiseLevel\.|^AtTheTip/HiddenTerm\..*/(k2|k3|fc)( |$)"
  repeats+="|^Discover\.(FromStepSineFundamentalsOfAccelerationOnly"
  repeats+="|TwoEffectsAtOnceCubicStiffnessAndDryFriction"
  repeats+="|TheEffectHidesAtOneOfTwoJointsAndTheOtherStaysLinear|ALinearModelErrorIsReportedAsLinear)$"
  # The command line's sweeps over every option and command (the same parser, once per option)
  # and its end-to-end runs of what the library's tests run instrumented.
  repeats+="|^CliTest\.(OptionsOutOfRangeAreNamedBeforeAnythingIsRead|EnumeratedOptionsListTheirChoices"
  repeats+="|EveryCommandHasHelp|FlagsShowNoDefaultAndEveryPictureHasNoPlot"
  repeats+="|EveryHarmonicBalanceTakesBalanceHarmonics|IdentifyThroughMeasuredFrfsAsThroughTheModel"
  repeats+="|RandomAndCompareCheckTheirOptions|DiscoverNamesAHiddenCubicStiffnessAndWritesItsReport)$"
  # Second methods by long time integration and sweeps over a parameter: the physics checks of
  # the harmonic balance, the modal time model and the fits against time integration, which run
  # uninstrumented in the main suite, while shorter tests run the same code instrumented
  # (HarmonicBalance.*, TimeModel.TwoModalSubstructuresJoined..., Continuation.Softening...,
  # SimulateSineTests.TimeIntegrationAndHarmonicBalanceAgree, SparseCholesky.SolvesLike...).
  # Instrumented times, 2026-12-05 (loaded machine): 63-338 s each, 1 300 of 1 770 test-seconds
  # in the first 274 tests.
  repeats+="|^HarmonicBalance\.(.*TimeIntegration|AnAsymmetricStartFindsTheSymmetryBreakingSteadyState)$"
  repeats+="|^TimeModel\.(LinearSteadyStateIsTheModalModelsReceptance"
  repeats+="|ModalModelAgreesWithTheFiniteElementModelItComesFrom)$"
  repeats+="|^FitTest\.(CoulombFrictionFromTimeIntegrationAmplitudeSweep"
  repeats+="|PaperModelIFromTimeIntegrationFrequencySweep)$|^Continuation\.HardeningCubicFoldsAndStability$"
  repeats+="|^SparseCholesky\.OwnBlockSolveEqualsCholmodsForEveryWidth$"
  repeats+="|^SimulateSineTests\.EveryTermAgreesWithTimeIntegrationHarmonicByHarmonic$"
  # Beyond those, every test that took over 1 s in the main suite's last run in ./build (ctest's
  # cost data; CI runs the main suite first), but the fastest of each suite, so that no suite's
  # code goes unchecked: the slow tests repeat the same code over sweeps and long time
  # integrations, instrumented several times slower (scripts/sanitized_selection.py). A suite
  # whose fastest test took over 3 s (a whole discovery per parameter: 15-25 times slower
  # instrumented) is left out whole; shorter discovery and identification tests run its code.
  # And every test that took over 15 s in an earlier instrumented run (scripts/sanitized_costs.txt:
  # mostly time integrations with dry friction, 30-50 times slower instrumented; the integrators'
  # own shorter tests run instrumented).
  costs=build/Testing/Temporary/CTestCostData.txt
  if [[ -f "$costs" ]]; then
    slow=$(python3 scripts/sanitized_selection.py "$costs" --limit 1 --suite-limit 3 \
      --instrumented scripts/sanitized_costs.txt --instrumented-limit 15 --report)
    [[ -n "$slow" ]] && repeats+="|$slow"
  else
    echo "run_tests_novtk: no $costs (the main suite has not run here): only the listed tests" \
      "are left out of the instrumented run" >&2
  fi
  exclude=(-E "_study$|^MonteCarlo/|^docs_|$repeats")
  # The example studies' checks are left out: their programs are not built.
  config+=(-DJOINTID_BUILD_EXAMPLES=OFF)
fi
bash scripts/setup.sh
# shellcheck source=scripts/compiler_cache.sh
source scripts/compiler_cache.sh
cmake -S . -B "$build" "${config[@]}" "${cache_cmake_args[@]}" -DJOINTID_WITH_VTK=OFF -DJOINTID_WITH_SLEPC=OFF \
  -DJOINTID_BUILD_TESTS=ON -DJOINTID_BUILD_BENCH=OFF "$@" >/dev/null
cmake --build "$build" -j "$(nproc)"
ctest --test-dir "$build" --output-on-failure --timeout 1800 -j "$(nproc)" "${exclude[@]}"
