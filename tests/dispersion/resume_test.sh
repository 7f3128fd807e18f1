#!/bin/sh
# A dispersion killed half-way (SIGKILL to its whole process group) and restarted runs only the
# missing draws and ends with the results file of an uninterrupted run, byte for byte.
# Usage: resume_test.sh ROCKSTEADY_CAMPAIGN SOURCE_DIR WORK_DIR
set -eu
exe=$1 src=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
sed -e 's/^draws: 40/draws: 12/' -e 's/^duration_s: 1.0e5/duration_s: 2.0e4/' \
    -e 's/^strategies: .*/strategies: [ntcl+dpd_ref, dpd]/' \
    "$src/configs/dispersions/prop5-sweep.yaml" > "$work/d.yaml"
run() { "$exe" dispersion "$work/d.yaml" --config-dir "$src/configs" --no-plots "$@"; }

run -o "$work/ref" --jobs 2 > "$work/ref.log" 2>&1

setsid "$exe" dispersion "$work/d.yaml" --config-dir "$src/configs" --no-plots -o "$work/run" --jobs 1 \
  > "$work/run1.log" 2>&1 &
pid=$!
n=0
for _ in $(seq 3000); do  # up to 150 s: a loaded machine writes its first draws late
  n=$(ls "$work/run/draws" 2>/dev/null | grep -c '\.json$' || true)
  [ "$n" -ge 3 ] && break
  sleep 0.05
done
kill -9 "-$pid" 2>/dev/null || kill -9 "$pid"  # dash's kill takes no "--"
wait "$pid" 2>/dev/null || true
sleep 0.2
done_before=$(ls "$work/run/draws" | grep -c '\.json$' || true)
echo "killed with $done_before of 12 draws written"
if [ "$done_before" -ge 12 ] || [ "$done_before" -lt 1 ]; then
  echo "FAIL: the kill did not land half-way ($done_before draws)"; exit 1
fi
run -o "$work/run" --jobs 2 > "$work/run2.log" 2>&1
cat "$work/run2.log"
expect="12 draws, $done_before already done, running $((12 - done_before))"
grep -q "$expect" "$work/run2.log" || { echo "FAIL: expected '$expect'"; exit 1; }
cmp "$work/ref/results.csv" "$work/run/results.csv"
echo "resumed results identical to the uninterrupted run"

# One draw re-flown alone (with its time series and plots) is the stored result bit for bit.
"$exe" dispersion "$work/d.yaml" --config-dir "$src/configs" -o "$work/run" --draw 5 > "$work/draw5.log" 2>&1
cat "$work/draw5.log"
grep -q "identical (bit for bit)" "$work/draw5.log"
[ -s "$work/run/draw-5/dpd/timeseries.csv" ]
