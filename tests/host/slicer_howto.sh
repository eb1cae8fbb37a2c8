#!/usr/bin/env bash
# docs/SLICER.md's "Try it without Slicer", as written: tissue-host on slicer_frog.toml and
# tissue-igtl-client pressing 6 mm; the client must get forces (about 2.6 N up at the end) and a surface.
# Usage: slicer_howto.sh TISSUE_HOST TISSUE_IGTL_CLIENT SOURCE_DIR WORK_DIR
set -euo pipefail
host=$1 client=$2 source=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
"$host" run "$source/host/scenarios/slicer_frog.toml" --duration 4 --no-rt-priority -q -o "$work/session" \
  > "$work/host.txt" 2>&1 &
host_pid=$!
"$client" --duration 3 --depth 6 --save-surface "$work/frog.vtk" | tee "$work/client.txt"
wait "$host_pid"
last_force=$(grep "^t " "$work/client.txt" | tail -1 | awk '{for (i = 1; i <= NF; ++i) if ($i == "force") print $(i + 3)}')
echo "last force z: $last_force N"
awk -v f="$last_force" 'BEGIN { exit !(f > 1.5 && f < 4.0) }' || { echo "force z out of (1.5, 4) N"; exit 1; }
grep -q "^POLYGONS" "$work/frog.vtk" || { echo "no surface saved"; exit 1; }
grep -q '"connections": 1' "$work/session/summary.json" || { echo "no connection in summary.json"; exit 1; }
