#!/usr/bin/env bash
# A newcomer's first command: installs what is missing, builds, and runs synbench on the
# embedded twin (until `synbench serve` exists: one emulated operating point).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh release
exec build/release/server/synbench point --speed-rpm 700 --load-Nm 2.5 --angle-deg 52 "$@"
