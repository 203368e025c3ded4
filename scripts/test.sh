#!/usr/bin/env bash
# The whole test suite: installs what is missing, builds (warnings as errors), runs every test,
# then builds the GoogleTest programs with AddressSanitizer and UndefinedBehaviorSanitizer
# (the asan preset) and the threaded ones with ThreadSanitizer (tsan) and runs them again.
# Arguments go to the first ctest run; SYNBENCH_TEST_SANITIZERS=0 skips the sanitized passes
# (about 20 minutes on 2 cores).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
# The API tools the tests run on the OpenAPI document (Redocly CLI, a generated client).
if command -v npm >/dev/null 2>&1; then scripts/npm-ci.sh tests/api-tools; fi
scripts/build.sh default
ctest --preset default -j"$(nproc)" "$@"
if [ "${SYNBENCH_TEST_SANITIZERS:-1}" != 0 ]; then
  cmake --preset asan >/dev/null
  cmake --build --preset asan -- -j"$(nproc)"
  ctest --preset asan -j"$(nproc)"
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan -- -j"$(nproc)"
  ctest --preset tsan -j"$(nproc)"
fi
