#!/usr/bin/env bash
# Configures and builds one CMake preset (default: "default"): scripts/build.sh [preset [target...]]
# With targets, only those (scripts/start.sh builds just `synbench`: the tests and benchmarks are
# test.sh's); without, every target of the preset.
# Also builds the web dashboard into web/dist (served by synbench serve): `npm ci` only when
# web/package-lock.json changed since the last install, `npm run build` only when a source changed.
set -euo pipefail
cd "$(dirname "$0")/.."
preset=${1:-default}
shift || true
targets=()
for t in "$@"; do targets+=(--target "$t"); done

if command -v npm >/dev/null 2>&1; then
  scripts/npm-ci.sh web
  (
    cd web
    if [ ! -f dist/index.html ] || [ -n "$(find index.html vite.config.js package-lock.json src -newer dist/index.html 2>/dev/null | head -1)" ]; then
      npm run --silent build -- --logLevel warn
    fi
  )
else
  echo "build: npm not found, the web dashboard (web/dist) is not built (scripts/install-deps.sh installs it)" >&2
fi

cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" "${targets[@]}" -- -j"$(nproc)"
