#!/usr/bin/env bash
# Runs the console's browser test inside a private network namespace (no network touched):
# rocksteady-plant and rocksteady-fsw in real time on an LCM bus, rocksteady-ground serve on
# loopback, and console_browser_test.mjs driving Debian's chromium. Screenshots and the processes'
# logs go to ARTEFACT_DIR.
# Usage: run_console_test.sh BUILD_DIR SOURCE_DIR ARTEFACT_DIR
set -euo pipefail
build=$1 src=$2 out=$3
mkdir -p "$out"
[[ -f "$src/ground/console/node_modules/puppeteer-core/package.json" ]] ||
  { echo "run_console_test: puppeteer-core missing: run scripts/setup.sh (npm ci in ground/console)"; exit 1; }
command -v chromium >/dev/null || { echo "run_console_test: chromium missing: run scripts/setup.sh"; exit 1; }
export RS_BUILD=$build RS_SRC=$src RS_OUT=$out
exec unshare -rn bash -c '
  set -u
  ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo
  url="udpm://239.255.76.67:7667?ttl=0"
  state=$(mktemp -d)
  cd "$RS_SRC"
  rm -f "$RS_OUT"/*.log "$RS_OUT"/*.png   # nothing of an earlier run is read or kept
  # A command key made for this run: the console signs, the flight verifies.
  "$RS_BUILD/ground/cli/rocksteady-ground" keygen "$state/key" > /dev/null
  "$RS_BUILD/fsw/main/rocksteady-fsw" --lcm-url "$url" --case 1 --clock realtime \
      --key-file "$state/key" --start-mode DETUMBLE --tlm-every 2 > "$RS_OUT/fsw.log" 2>&1 & fsw=$!
  "$RS_BUILD/ground/plantd/rocksteady-plant" --lcm-url "$url" --case 1 --mode realtime \
      --truth-every 2 > "$RS_OUT/plant.log" 2>&1 & plant=$!
  "$RS_BUILD/ground/cli/rocksteady-ground" --lcm-url "$url" --key-file "$state/key" serve --port 0 --state-dir "$state" \
      --stale-after 2 > "$RS_OUT/serve.log" 2>&1 & serve=$!
  trap "kill $fsw $plant $serve 2>/dev/null; rm -rf $state" EXIT
  for i in $(seq 150); do grep -q "^console: http" "$RS_OUT/serve.log" && break; sleep 0.2; done
  console=$(sed -n "s/^console: \(http[^ ]*\).*/\1/p" "$RS_OUT/serve.log")
  [[ -n "$console" ]] || { echo "serve did not start:"; cat "$RS_OUT/serve.log"; exit 1; }
  echo "console at $console"
  RS_NODE_MODULES="$RS_SRC/ground/console/node_modules" node "${RS_TEST_SCRIPT:-$RS_SRC/tests/console/console_browser_test.mjs}" \
      "$console" "$RS_OUT" $plant $fsw
'
