#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds (warnings as errors), runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh default
ctest --preset default -j"$(nproc)" "$@"
