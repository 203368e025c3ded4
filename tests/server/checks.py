"""The checks of a Python test script (tests/server, tests/perf): each printed as it fails (and as
it passes when verbose), the failures kept, the script's exit status from them. Standard library
only.

    check = Checks(verbose=True)
    check(status == 200, "health 200 (%s)" % status)
    check.finish("serve test ok")   # exit 1 after "N failure(s)", else prints "serve test ok"
"""
import sys


class Checks:
    def __init__(self, verbose=False):
        self.verbose = verbose
        self.failures = []  # what failed, in order

    def __call__(self, cond, what):
        if not cond:
            self.failures.append(what)
            print("FAIL:", what, flush=True)
        elif self.verbose:
            print("ok:", what, flush=True)
        return cond

    def finish(self, passed):
        """Exits 1 if anything failed; otherwise prints `passed` (and returns)."""
        if self.failures:
            print("%d failure(s)" % len(self.failures), flush=True)
            sys.exit(1)
        print(passed, flush=True)
