#!/usr/bin/env python3
"""Which tests the instrumented run leaves to the uninstrumented one, from the latter's times.

Usage: sanitized_selection.py COST_DATA [--limit SECONDS] [--suite-limit SECONDS]
                               [--instrumented COST_DATA --instrumented-limit SECONDS] [--report]

COST_DATA is ctest's own record of the main suite's run (build/Testing/Temporary/
CTestCostData.txt: a line "<test> <runs> <average seconds>" per test). Under AddressSanitizer
and UndefinedBehaviorSanitizer a test runs several times slower, and the slowest tests are the
ones that repeat the same code many times (parameter sweeps, long time integrations, repeated
discoveries): they add time, not coverage. So the instrumented run takes every test that took
at most --limit seconds uninstrumented (default 1) and, of every GoogleTest suite (the name up
to its first '.', e.g. "Discover" or "AtTheTip/HiddenTerm"), at least its fastest test, so
that no suite's code goes unchecked — unless that fastest test itself took over --suite-limit
seconds (default: no limit): a suite whose every test is that long (a discovery run per
parameter) repeats code that shorter tests of other suites run instrumented, and runs 15-25
times slower under the sanitizers (AtTheTip/HiddenParametricTerm.*/jenkins: 4.5 s, 86-103 s
instrumented). A test's instrumented time is not a fixed multiple of its plain one (time
integration with dry friction runs 30-50 times slower under ASan and UBSan, parsing 3-5 times):
with --instrumented, the cost data of an earlier instrumented run (scripts/sanitized_costs.txt:
CI's fresh clone has none of its own), every test it timed over --instrumented-limit seconds
(default 10) is left out as well, its suite's fastest included. Prints a ctest regular expression that matches the tests
left out (one alternative per test, anchored), or nothing when none is; with --report, a table
of what is left out and what stays, on stderr.
"""
import re
import sys


def read_costs(path):
    costs = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.rstrip("\n")
            if line == "---":  # the failed tests' names follow
                break
            if line.startswith("#"):  # a comment (scripts/sanitized_costs.txt)
                continue
            parts = line.rsplit(" ", 2)
            if len(parts) != 3:
                continue
            name, _, cost = parts
            try:
                costs[name] = float(cost)
            except ValueError:
                raise SystemExit(f"{path}: '{line}': expected '<test> <runs> <seconds>'")
    return costs


def suite(name):
    return name.split(".", 1)[0] if "." in name else name


def main(argv):
    if not argv or argv[0].startswith("-"):
        raise SystemExit(__doc__)
    path, limit, suite_limit, report = argv[0], 1.0, float("inf"), False
    instrumented_path, instrumented_limit = None, 10.0
    rest = argv[1:]

    def seconds(option, text):
        try:
            return float(text)
        except ValueError:
            raise SystemExit(f"{option}: expected seconds, got '{text}'")

    while rest:
        option = rest[0]
        if option in ("--limit", "--suite-limit", "--instrumented-limit") and len(rest) > 1:
            value = seconds(option, rest[1])
            if option == "--limit":
                limit = value
            elif option == "--suite-limit":
                suite_limit = value
            else:
                instrumented_limit = value
            rest = rest[2:]
        elif option == "--instrumented" and len(rest) > 1:
            instrumented_path, rest = rest[1], rest[2:]
        elif option == "--report":
            report, rest = True, rest[1:]
        else:
            raise SystemExit(f"unknown argument '{option}'\n{__doc__}")
    costs = read_costs(path)
    fastest = {}
    for name, cost in costs.items():
        s = suite(name)
        if s not in fastest or cost < costs[fastest[s]]:
            fastest[s] = name
    kept = {n for n in costs if costs[n] <= limit} | {
        n for n in fastest.values() if costs[n] <= suite_limit}
    slow_instrumented = {}
    if instrumented_path:
        slow_instrumented = {n: t for n, t in read_costs(instrumented_path).items()
                             if t > instrumented_limit and n in costs}
        kept -= set(slow_instrumented)
    left = sorted((n for n in costs if n not in kept), key=lambda n: -costs[n])
    if report:
        total = sum(costs.values())
        out = sum(costs[n] for n in left)
        print(f"{len(costs)} tests, {total:.0f} s uninstrumented; left out: {len(left)} "
              f"({out:.0f} s); instrumented: {len(costs) - len(left)} "
              f"({total - out:.0f} s)", file=sys.stderr)
        for n in left:
            why = (f" ({slow_instrumented[n]:.1f} s instrumented)" if n in slow_instrumented
                   else "")
            print(f"  left out {costs[n]:8.2f} s  {n}{why}", file=sys.stderr)
        for n in sorted(kept - {n for n in costs if costs[n] <= limit}, key=lambda n: -costs[n]):
            print(f"  kept     {costs[n]:8.2f} s  {n} (its suite's fastest)", file=sys.stderr)
    if left:
        print("|".join("^" + re.sub(r"([\\.^$|()\[\]*+?{}])", r"\\\1", n) + "$" for n in left))


if __name__ == "__main__":
    main(sys.argv[1:])
