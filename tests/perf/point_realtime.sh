#!/usr/bin/env bash
# Real-time factor of a whole `synbench point --window-s 60` process: bench time / wall time.
# usage: tests/perf/point_realtime.sh [path/to/synbench]
set -euo pipefail
bin=${1:-build/release/server/synbench}
start=$(date +%s.%N)
out=$("$bin" point --speed-rpm 700 --load-Nm 2.5 --angle-deg 52 --window-s 60)
end=$(date +%s.%N)
bench_s=$(sed -n 's/.*(twin, \([0-9.e+]*\) s of bench time).*/\1/p' <<<"$out")
python3 - "$bench_s" "$start" "$end" <<'PY'
import sys
bench, t0, t1 = map(float, sys.argv[1:])
wall = t1 - t0
print(f"synbench point --window-s 60: {bench:.2f} s of bench time in {wall:.3f} s wall: "
      f"real-time factor {bench / wall:.0f}x ({wall / bench * 100:.3f} us of wall time per 100 us step)")
PY
