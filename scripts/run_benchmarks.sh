#!/usr/bin/env bash
# Runs every benchmark binary (bench_*) in DIR with repetitions and prints medians, then the
# accuracy programs (accuracy_*), which print their own tables. BENCH_REPETITIONS sets the
# repetitions (default 5); ACCURACY_TREES the trees per preset (default 4).
set -euo pipefail
dir="${1:?usage: run_benchmarks.sh DEVEL_LIB_DIR}"
reps="${BENCH_REPETITIONS:-5}"
status=0
for b in "$dir"/bench_*; do
  [[ -x "$b" ]] || continue
  echo "== $(basename "$b") (median of $reps where repeated)"
  "$b" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
       --benchmark_counters_tabular=true 2>&1 | grep -Ev '_(mean|stddev|cv) ' || status=1
done
for a in "$dir"/accuracy_*; do
  [[ -x "$a" ]] || continue
  echo "== $(basename "$a")"
  "$a" --trees "${ACCURACY_TREES:-4}" || status=1
done
exit $status
