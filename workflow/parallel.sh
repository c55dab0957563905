#!/usr/bin/env bash
# textile batch on GNU parallel, for machines without a scheduler (docs/guide/batch.md,
# "Scale"): one job a specimen (`--shard K/N`, N the number of rows), logged to DIR/joblog;
# run it again after an interruption and `--resume` skips the jobs the log has as done. Then
# the summary (every specimen resumed) and the lab report.
#   bash workflow/parallel.sh MANIFEST.csv DIR [JOBS]      (TEXTILE=path/to/textile to choose)
# Other hosts: add parallel's --sshloginfile with DIR on a shared file system.
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: bash workflow/parallel.sh MANIFEST.csv DIR [JOBS]" >&2; exit 2; }
manifest="$1" out="$2" jobs="${3:-$(nproc)}"
textile="${TEXTILE:-textile}"
# Rows: non-blank lines after the header, as textile counts them.
rows=$(grep -c '[^[:space:]]' "$manifest")
rows=$((rows - 1))
((rows > 0)) || { echo "error: $manifest has no specimens" >&2; exit 2; }
mkdir -p "$out"
# A specimen that fails (exit 3) is a result, listed in the summary: not a failed job.
seq 1 "$rows" | parallel --will-cite --jobs "$jobs" --joblog "$out/joblog" --resume \
  "'$textile' batch '$manifest' -o '$out' --shard {}/$rows > /dev/null || [ \$? -eq 3 ]"
status=0
"$textile" batch "$manifest" -o "$out" --resume || status=$?
"$textile" report "$out" -o "$out/report.html"
exit "$status"
