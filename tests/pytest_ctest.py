"""Runs pytest for one CTest test so that CTest sees a skip: exits 77 (the Python tests' SKIP_RETURN_CODE,
tests/python/CMakeLists.txt) when something was skipped and nothing passed or failed, else pytest's own
status. pytest's -rs lists every skip with its reason, so a skip beside passing tests shows in the output.

usage: python3 tests/pytest_ctest.py PYTEST_ARGUMENTS...
"""
import collections
import sys

import pytest

SKIPPED = 77


class Outcomes:
    """Counts the outcomes of test phases and of collection (a module-level importorskip skips there)."""

    def __init__(self) -> None:
        self.counts: collections.Counter = collections.Counter()

    def pytest_collectreport(self, report) -> None:
        if report.outcome != "passed":
            self.counts[report.outcome] += 1

    def pytest_runtest_logreport(self, report) -> None:
        if hasattr(report, "wasxfail"):
            self.counts["passed"] += 1  # an expected failure ran to its expected end
        elif report.when == "call" or report.outcome != "passed":
            self.counts[report.outcome] += 1


def main(argv: list[str]) -> int:
    outcomes = Outcomes()
    status = pytest.main(["-rs", *argv], plugins=[outcomes])
    only_skips = outcomes.counts["skipped"] > 0 and outcomes.counts["passed"] == outcomes.counts["failed"] == 0
    if status in (pytest.ExitCode.OK, pytest.ExitCode.NO_TESTS_COLLECTED) and only_skips:
        print(f"pytest_ctest: nothing ran but {outcomes.counts['skipped']} skip(s): exit {SKIPPED}, a CTest skip")
        return SKIPPED
    return int(status)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
