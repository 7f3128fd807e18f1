#!/usr/bin/env bash
# Runs every libFuzzer target of the build (tests/fuzz: the five decoder fuzzers and the stateful
# whole-inbound-path fuzzer) for a given time each and reports, per target, the executions, the
# coverage (edges: libFuzzer's "cov", features: "ft") and the corpus size. The stateful fuzzer
# starts from a copy of the kept corpus (tests/fuzz/corpus/stateful); --keep merges what it found
# back into that corpus (minimised: only inputs that add coverage).
#
# Usage: scripts/fuzz.sh [SECONDS] [--build DIR] [--out DIR] [--keep] [--only NAME]
#   SECONDS      run time of each target (default 60)
#   --build DIR  build tree with the fuzzers (default build/release; cmake --build ... --target
#                rocksteady_fuzzers)
#   --out DIR    work folder: corpora, crash artefacts, logs (default out/fuzz)
#   --keep       merge the stateful fuzzer's new inputs into tests/fuzz/corpus/stateful
#   --only NAME  one target (sensor_frame, thruster_cmd, ground_cmd, trajectory_chunk,
#                ground_inbound, stateful)
# Exit status: 0 no crash, 1 a target crashed (its artefact is in the work folder), 2 usage.
set -euo pipefail
cd "$(dirname "$0")/.."
secs=60 build=build/release out=out/fuzz keep=0 only=""
usage_error() { echo "fuzz.sh: $*  (scripts/fuzz.sh --help)" >&2; exit 2; }
while (($#)); do
  case "$1" in
    --build) [[ $# -ge 2 ]] || usage_error "--build needs a value"; build="$2"; shift 2 ;;
    --out) [[ $# -ge 2 ]] || usage_error "--out needs a value"; out="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    --only) [[ $# -ge 2 ]] || usage_error "--only needs a value"; only="$2"; shift 2 ;;
    -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) usage_error "unknown option $1" ;;
    *) [[ "$1" =~ ^[1-9][0-9]*$ ]] || usage_error "SECONDS $1: a positive whole number"; secs="$1"; shift ;;
  esac
done
names=(sensor_frame thruster_cmd ground_cmd trajectory_chunk ground_inbound stateful)
[[ -z "$only" || " ${names[*]} " == *" $only "* ]] || usage_error "--only $only: one of ${names[*]}"
mkdir -p "$out"
printf '%-18s %8s %12s %10s %8s %8s %s\n' target seconds executions exec/s cov ft corpus
rc=0
for name in "${names[@]}"; do
  [[ -n "$only" && "$name" != "$only" ]] && continue
  bin="$build/tests/fuzz/fuzz_$name"
  [[ -x "$bin" ]] || { echo "fuzz.sh: $bin not built (cmake --build --preset release --target rocksteady_fuzzers)" >&2; rc=2; continue; }
  work="$out/$name"
  mkdir -p "$work/corpus"
  if [[ "$name" == stateful ]]; then
    cp -n tests/fuzz/corpus/stateful/* "$work/corpus/" 2>/dev/null || true
    seed_env=()
  else
    seed_env=(env ROCKSTEADY_FUZZ_SEED_DIR="$work/corpus")
  fi
  log="$work/run.log"
  set +e
  "${seed_env[@]}" "$bin" -max_total_time="$secs" -print_final_stats=1 -rss_limit_mb=2048 \
      -artifact_prefix="$work/" "$work/corpus" > "$log" 2>&1
  status=$?
  set -e
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
  files=$(find "$work/corpus" -type f | wc -l)
  printf '%-18s %8s %12s %10s %8s %8s %s\n' "$name" "$secs" "${execs:-?}" "${speed:-?}" "${cov:-?}" "${ft:-?}" "$files"
  if ((status != 0)); then
    echo "fuzz.sh: fuzz_$name failed (exit $status): $(grep -m1 -E 'ERROR|deadly signal' "$log" || true); log $log" >&2
    rc=1
  fi
  if ((keep)) && [[ "$name" == stateful && $status -eq 0 ]]; then
    "$bin" -merge=1 -rss_limit_mb=2048 tests/fuzz/corpus/stateful "$work/corpus" > "$work/merge.log" 2>&1
    echo "kept corpus: $(find tests/fuzz/corpus/stateful -type f | wc -l) inputs in tests/fuzz/corpus/stateful"
  fi
done
exit $rc
