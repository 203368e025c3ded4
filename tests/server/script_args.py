"""The command line of a Python test or benchmark script (tests/server, tests/perf):
`SCRIPT path/to/synbench [--name VALUE]... [--flag]`. Standard library only."""
import sys


def option(name, default):
    """The value after `name` on the command line, of the type of `default`; `default` without it."""
    return type(default)(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def flag(name):
    return name in sys.argv
