#!/usr/bin/env bash
# scripts/pil.sh checks every argument before it starts anything: a bad one exits 2 with a message
# naming it, and nothing is run (no output folder is created).
set -u
root=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail=0
expect() {  # expect CODE MESSAGE ARGS...
  local code=$1 msg=$2; shift 2
  local err rc
  err=$("$root/scripts/pil.sh" "$@" --out "$out/run" 2>&1 >/dev/null); rc=$?
  if [[ $rc -ne $code || "$err" != *"$msg"* ]]; then
    echo "FAIL pil.sh $*: exit $rc, said: $err (expected exit $code and '$msg')"; fail=1
  else
    echo "PASS pil.sh $*: exit $rc: $err"
  fi
  [[ ! -e "$out/run" ]] || { echo "FAIL pil.sh $*: created its output folder"; fail=1; }
}
expect 2 "case 9: no configs/cases/case9.yaml (cases: 1 2 3 4 5 6 7)" 9
expect 2 "--law pid: not a control law (one of: ntcl, el," --law pid
expect 2 "--duration -5: a positive number" --duration -5
expect 2 "--duration 0: a positive number" --duration 0
expect 2 "--mode fast: lockstep or realtime" --mode fast
expect 2 "--tlm-every 1.5: a positive whole number" --tlm-every 1.5
expect 2 "--port 70000: 1..65535" --port 70000
expect 2 "--law needs a value" --law
expect 2 "unknown option --bogus" --bogus
expect 2 "case file nowhere.yaml: not found" nowhere.yaml
exit $fail
