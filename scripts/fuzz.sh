#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ with clang (address and undefined-behaviour sanitizers)
# and runs each for FUZZ_SECONDS (default 60) from its seed corpus. Exits non-zero on a crash,
# leaving the input as .build/fuzz/crash-*.
#   lms111_fuzz: the LMS111's bytes and recordings (seeds fuzz/corpus)
#   files_fuzz:  point cloud files, model and truth JSON, Ensemble replies (fuzz/corpus_files)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="$root/.build/fuzz"
seconds="${FUZZ_SECONDS:-60}"
bash "$root/scripts/setup.sh" "$root/scripts/debian-packages-fuzz.txt"
flags=(-std=c++17 -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
  -I"$root/include" -I/usr/include/eigen3)
common=("$root/src/common/error.cpp" "$root/src/common/printable.cpp" "$root/src/common/statistics.cpp")

build() {  # name, sources..., then -- and link flags
  local name=$1
  shift
  local files=() links=()
  while (($#)) && [[ $1 != -- ]]; do files+=("$1"); shift; done
  (($#)) && shift
  links=("$@")
  echo "fuzz: building $name"
  clang++ "${flags[@]}" "$root/fuzz/$name.cpp" "${common[@]}" "${files[@]}" -o "$out/$name" \
    "${links[@]}"
}

run() {  # name, corpus folder
  local name=$1 seeds=$2 status=0
  mkdir -p "$out/corpus_$name"
  cp -n "$seeds"/* "$out/corpus_$name/" 2>/dev/null || true
  echo "fuzz: $name for ${seconds} s"
  (cd "$out" && "./$name" -max_total_time="$seconds" -max_len=16384 -rss_limit_mb=2048 \
    -print_final_stats=1 "corpus_$name" > "$name.log" 2>&1) || status=$?
  grep -E '^(Done|stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb)|ERROR|SUMMARY|runtime error' \
    "$out/$name.log" || true
  if ((status)); then
    echo "fuzz: $name FAILED (exit $status); log: $out/$name.log; inputs: $out/crash-*" >&2
  else
    echo "fuzz: $name: no crash in ${seconds} s"
  fi
  return $status
}

mkdir -p "$out"
lms111=()
for s in lms111/cola lms111/cola_fields lms111/scan_telegram lms111/laser_scan lms111/capture \
  lms111/requests emulation/lms111_emulator emulation/scan_source emulation/session_replay; do
  lms111+=("$root/src/$s.cpp")
done
build lms111_fuzz "${lms111[@]}"
files=("$root/src/io/point_cloud_io.cpp" "$root/src/io/pcl_file_io.cpp" "$root/src/io/xyz_text_io.cpp"
  "$root/src/io/tree_json.cpp" "$root/src/modeling/tree_model.cpp"
  "$root/src/aerotech/ascii_protocol.cpp")
build files_fuzz "${files[@]}" -- -I/usr/include/pcl-1.13 -lpcl_io \
  -lpcl_common -lboost_system
status=0
run lms111_fuzz "$root/fuzz/corpus" || status=$?
run files_fuzz "$root/fuzz/corpus_files" || status=$?
exit $status
