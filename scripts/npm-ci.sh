#!/usr/bin/env bash
# `npm ci` in DIR (a folder with package.json and package-lock.json), only when its lock file
# changed since the last install there: scripts/npm-ci.sh DIR. Used for the dashboard (web/, by
# build.sh) and the API tools the tests run (tests/api-tools/, by test.sh).
set -euo pipefail
cd "$1"
stamp=node_modules/.synbench-lock
if [ ! -f "$stamp" ] || ! cmp -s package-lock.json "$stamp"; then
  npm ci --no-audit --no-fund --loglevel=error
  cp package-lock.json "$stamp"
fi
