#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds (warnings as errors), runs every test,
# then builds the GoogleTest programs with AddressSanitizer and UndefinedBehaviorSanitizer
# (the asan preset) and runs them again. Arguments go to the first ctest run;
# SYNBENCH_TEST_SANITIZERS=0 skips the sanitized pass (about 12 minutes on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh default
ctest --preset default -j"$(nproc)" "$@"
if [ "${SYNBENCH_TEST_SANITIZERS:-1}" != 0 ]; then
  cmake --preset asan >/dev/null
  cmake --build --preset asan -- -j"$(nproc)"
  ctest --preset asan -j"$(nproc)"
fi
