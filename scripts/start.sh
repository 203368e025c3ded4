#!/usr/bin/env bash
# A newcomer's first command: installs what is missing, builds, and starts the synbench daemon
# on the embedded twin with the dashboard at http://127.0.0.1:8080 (and the REST API under /api).
# The operator token is printed on first start and kept in synbench-data/operator.token.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh release synbench  # the daemon alone; the tests are test.sh's
exec build/release/server/synbench serve --listen 127.0.0.1:8080 "$@"  # data: ./synbench-data
