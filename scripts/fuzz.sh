#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (address and undefined-behaviour sanitizers)
# and runs each for FUZZ_SECONDS (default 60) from the seed corpus in fuzz/corpus. Exits
# non-zero on a crash, leaving the input as .build/fuzz/crash-*.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$root/.build/fuzz"
seconds="${FUZZ_SECONDS:-60}"
bash "$root/scripts/setup.sh" "$root/scripts/debian-packages-fuzz.txt"
mkdir -p "$out/corpus"
cp -n "$root"/fuzz/corpus/* "$out/corpus/" 2>/dev/null || true
# The code that reads the device's bytes, compiled into the fuzzer with the sanitizers.
sources=(cola cola_fields scan_telegram laser_scan device_emulator scan_source capture requests
  session_replay)
files=("$root/fuzz/lms111_fuzz.cpp" "$root/src/common/error.cpp" "$root/src/common/printable.cpp")
for s in "${sources[@]}"; do files+=("$root/src/lms111/$s.cpp"); done
echo "fuzz: building lms111_fuzz"
clang++ -std=c++17 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
  -I"$root/include" "${files[@]}" -o "$out/lms111_fuzz"
echo "fuzz: lms111_fuzz for ${seconds} s"
cd "$out"
status=0
./lms111_fuzz -max_total_time="$seconds" -max_len=16384 -rss_limit_mb=2048 -print_final_stats=1 \
  corpus > lms111_fuzz.log 2>&1 || status=$?
grep -E '^(Done|stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb)|ERROR|SUMMARY|runtime error' lms111_fuzz.log || true
if ((status)); then
  echo "fuzz: lms111_fuzz FAILED (exit $status); log: $out/lms111_fuzz.log; inputs: $out/crash-*" >&2
else
  echo "fuzz: lms111_fuzz: no crash in ${seconds} s"
fi
exit $status
