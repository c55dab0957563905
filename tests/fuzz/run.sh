#!/usr/bin/env bash
# Short fuzz run of every parser target: bash tests/fuzz/run.sh [SECONDS_EACH=60]
# Builds with clang + libFuzzer + ASan/UBSan in build-fuzz/, runs each target on a copy of its
# seed corpus (tests/fuzz/corpus/<target>/). A crash leaves crash-* files in build-fuzz/findings:
# turn each into a regression test (a file in tests/data/... and an EXPECT in the parser's test).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
seconds="${1:-60}"
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DTEXTILE_FUZZ=ON -DTEXTILE_BUILD_TESTS=OFF "-DTEXTILE_SANITIZE=address;undefined" >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target fuzz_material fuzz_profile_csv
mkdir -p build-fuzz/findings
status=0
for t in material profile_csv; do
  work="build-fuzz/corpus/$t"
  mkdir -p "$work"
  cp -n tests/fuzz/corpus/"$t"/* "$work"/ 2>/dev/null || true
  echo "fuzz_$t: ${seconds}s"
  if ! build-fuzz/tests/fuzz/fuzz_"$t" -max_total_time="$seconds" -max_len=4096 -timeout=10 \
      -artifact_prefix=build-fuzz/findings/"$t"- "$work" > "build-fuzz/findings/$t.log" 2>&1; then
    echo "fuzz_$t: FOUND A PROBLEM, see build-fuzz/findings/$t.log"; status=1
  else
    tail -n 1 "build-fuzz/findings/$t.log"
  fi
done
exit $status
