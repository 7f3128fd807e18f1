#!/bin/sh
# The Slurm back end against the local one: a one-node Slurm (scripts/slurm-local.sh) runs a small
# dispersion as an sbatch array; its results file must equal the local back end's byte for byte.
# Exit 77 (skipped) only when not root: CI runs as root, so it runs there.
# Usage: slurm_test.sh ROCKSTEADY_CAMPAIGN SOURCE_DIR WORK_DIR
set -eu
exe=$1 src=$2 work=$3
if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: a local Slurm needs root (munged, slurmd)"
  exit 77
fi
"$src/scripts/slurm-local.sh" stop "$work/slurm-state" > /dev/null 2>&1 || true
rm -rf "$work"
mkdir -p "$work"
state="$work/slurm-state"
trap '"$src/scripts/slurm-local.sh" stop "$state" || true' EXIT
ROCKSTEADY_SLURM_PORT=${ROCKSTEADY_SLURM_PORT:-16827} "$src/scripts/slurm-local.sh" start "$state"
export SLURM_CONF="$state/slurm.conf"

# 8 draws of 2e4 s, fuel-optimal (one plan per draw, inside the back end) and D+PD-based tracking
# (planning dominates the time: a few seconds per draw).
sed -e "s/^draws: 40/draws: 8/" -e 's/^duration_s: 1.0e5/duration_s: 2.0e4/' \
    "$src/configs/dispersions/prop5-sweep.yaml" > "$work/d.yaml"
t0=$(date +%s.%N)
"$exe" dispersion "$work/d.yaml" --config-dir "$src/configs" --no-plots -o "$work/local" --jobs 2 \
  > "$work/local.log" 2>&1 || { cat "$work/local.log"; exit 1; }
t1=$(date +%s.%N)
"$exe" dispersion "$work/d.yaml" --config-dir "$src/configs" --no-plots -o "$work/slurm" \
  --backend slurm --shards 4 > "$work/slurm.log" 2>&1 || { cat "$work/slurm.log"; exit 1; }
t2=$(date +%s.%N)
cat "$work/slurm.log"
echo "local back end $(awk "BEGIN{print $t1 - $t0}") s wall, Slurm back end $(awk "BEGIN{print $t2 - $t1}") s wall"
ls "$work/slurm/slurm/" | grep -q 'task-.*_3.out' || { echo "FAIL: no array task 3 output"; exit 1; }
cmp "$work/local/results.csv" "$work/slurm/results.csv"
echo "Slurm results identical to the local back end's ($(wc -l < "$work/local/results.csv") lines)"
