#!/usr/bin/env bash
# Short fuzz run of every target: bash tests/fuzz/run.sh [SECONDS_EACH=60] [TARGET...]
# Builds with clang + libFuzzer + ASan/UBSan in build-fuzz/, runs each target on a copy of its
# seed corpus (tests/fuzz/corpus/<target>/). Targets: material, profile_csv, seam, seam_samples,
# rig, photo, cli (default: all). A finding leaves crash-*/leak-*/timeout-* files in
# build-fuzz/findings: commit it under tests/fuzz/crashes/<target>/ and turn it into a
# regression test (a file in tests/data/... or tests/bad_inputs/ and an EXPECT in the parser's
# test).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
seconds="${1:-60}"
shift || true
targets=("$@")
((${#targets[@]})) || targets=(material profile_csv seam seam_samples rig photo cli)
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DTEXTILE_FUZZ=ON -DTEXTILE_BUILD_TESTS=OFF "-DTEXTILE_SANITIZE=address;undefined" >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target "${targets[@]/#/fuzz_}"
mkdir -p build-fuzz/findings
# fontconfig's process-lifetime caches (Cairo text in the CLI's charts) are not leaks of ours.
export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
status=0
for t in "${targets[@]}"; do
  # Absolute paths: fuzz_cli changes into its scratch folder before libFuzzer reads them.
  work="$PWD/build-fuzz/corpus/$t"
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/"$t"/* "$work"/ 2>/dev/null || true
  # Photos need room for a small image; the others are text.
  max_len=4096
  [ "$t" = photo ] && max_len=65536
  echo "fuzz_$t: ${seconds}s"
  if ! build-fuzz/tests/fuzz/fuzz_"$t" -max_total_time="$seconds" -max_len="$max_len" -timeout=10 \
      -rss_limit_mb=3072 -artifact_prefix="$PWD/build-fuzz/findings/$t-" "$work" \
      > "build-fuzz/findings/$t.log" 2>&1; then
    echo "fuzz_$t: FOUND A PROBLEM, see build-fuzz/findings/$t.log"; status=1
  else
    grep -E '^(#[0-9]+|Done)' "build-fuzz/findings/$t.log" | tail -n 1
  fi
done
exit $status
