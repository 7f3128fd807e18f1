#!/usr/bin/env bash
# Processor-in-the-loop demo: rocksteady-plant, rocksteady-fsw and lcm-logger as separate processes on
# an LCM bus inside a private network namespace (works on any machine, touches no network), one case
# in lockstep; prints the plant's summary (SPEC §7 figures of merit, bus statistics) and leaves an
# LCM log for lcm-logplayer / lcm-spy.
#
# Usage: scripts/pil.sh [CASE] [options]
#   CASE                 case number (configs/cases/caseN.yaml) or a case file (default 1)
#   --law NAME           control law of the flight software (default ntcl: the ntcl+dpd_ref strategy)
#   --duration S         simulated seconds (default: the case's)
#   --mode M             lockstep (default) or realtime (wall clock: 10^5 s take 10^5 s)
#   --tlm-every N        telemetry and truth every N ticks (default 100 = every 10 s simulated)
#   --log-all            also log RS_SENSORS and RS_THRUSTER_CMD (10^6 messages each for case 1)
#   --build DIR          build tree with the programs (default build/release)
#   --out DIR            output folder (default out/pil): <case>.lcmlog, <case>.csv, <case>.*.log
#   --port P             LCM port inside the namespace (default 7667)
#   --one-bus            every channel on one bus (the default for --mode realtime and --log-all);
#                        otherwise lockstep runs on three buses, sensor frames on port P, thruster
#                        commands on P+1, ground channels (logged) on P+2, with the hot channels read
#                        directly by each loop (--direct-rx): several times faster, the same figures
# Commanding is authenticated: each run makes a fresh command key file <out>/<case>.key (mode 0600,
# `rocksteady-ground keygen`) for the flight software; ground tools use it with --key-file.
# Exit status: 0 ok, 1 the run failed (the children's last lines are printed), 2 usage error.
# Live on a workstation with lcm-spy instead: see fsw/main/README.md.
set -euo pipefail
cd "$(dirname "$0")/.."

case_arg=1 law=ntcl duration="" mode=lockstep tlm_every=100 log_all=0 build=build/release out=out/pil
port=7667 one_bus=0
usage_error() { echo "pil.sh: $*  (scripts/pil.sh --help)" >&2; exit 2; }
# The value of option $1, which must be there.
value() { [[ $# -ge 2 && -n "$2" && "$2" != --* ]] || usage_error "$1 needs a value"; }
while (($#)); do
  case "$1" in
    --law) value "$@"; law="$2"; shift 2 ;;
    --duration) value "$@"; duration="$2"; shift 2 ;;
    --mode) value "$@"; mode="$2"; shift 2 ;;
    --tlm-every) value "$@"; tlm_every="$2"; shift 2 ;;
    --log-all) log_all=1; shift ;;
    --build) value "$@"; build="$2"; shift 2 ;;
    --out) value "$@"; out="$2"; shift 2 ;;
    --port) value "$@"; port="$2"; shift 2 ;;
    --one-bus) one_bus=1; shift ;;
    -h|--help) sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) usage_error "unknown option $1" ;;
    *) case_arg="$1"; shift ;;
  esac
done

# Every argument is checked before anything starts, and the message names it.
laws="ntcl el integral adaptive so3 dpd feedforward"
[[ " $laws " == *" $law "* ]] || usage_error "--law $law: not a control law (one of: ${laws// /, })"
[[ "$mode" == lockstep || "$mode" == realtime ]] || usage_error "--mode $mode: lockstep or realtime"
if [[ -n "$duration" ]]; then
  [[ "$duration" =~ ^[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$ ]] && awk "BEGIN{exit !($duration > 0)}" ||
    usage_error "--duration $duration: a positive number of simulated seconds"
fi
[[ "$tlm_every" =~ ^[1-9][0-9]*$ ]] || usage_error "--tlm-every $tlm_every: a positive whole number of ticks"
[[ "$port" =~ ^[0-9]+$ ]] && ((port >= 1 && port <= 65535)) || usage_error "--port $port: 1..65535"
if [[ "$case_arg" =~ ^[0-9]+$ ]]; then
  if [[ ! -f "configs/cases/case$case_arg.yaml" ]]; then
    have=$(ls configs/cases 2>/dev/null | sed -n 's/^case\([0-9]*\)\.yaml$/\1/p' | sort -n | tr '\n' ' ')
    usage_error "case $case_arg: no configs/cases/case$case_arg.yaml (cases: ${have% })"
  fi
elif [[ ! -f "$case_arg" ]]; then
  usage_error "case file $case_arg: not found"
fi

fsw="$build/fsw/main/rocksteady-fsw"
plant="$build/ground/plantd/rocksteady-plant"
ground="$build/ground/cli/rocksteady-ground"
for p in "$fsw" "$plant" "$ground"; do
  [[ -x "$p" ]] || { echo "pil.sh: $p not found: build first (cmake --preset release && cmake --build --preset release)" >&2; exit 2; }
done
command -v lcm-logger >/dev/null || { echo "pil.sh: lcm-logger not found (apt-get install liblcm-bin)" >&2; exit 2; }
command -v unshare >/dev/null || { echo "pil.sh: unshare not found (util-linux)" >&2; exit 2; }

if [[ "$case_arg" =~ ^[0-9]+$ ]]; then name="case$case_arg"; else name="$(basename "$case_arg" .yaml)"; fi
mkdir -p "$out"
log="$out/$name.lcmlog"
rm -f "$log"
# A fresh command key for this run (never committed, never reused): the flight software verifies
# every ground command with it; its replay state goes beside it.
key="$out/$name.key"
rm -f "$key" "$key.state"
"$ground" keygen "$key" > /dev/null
channels='RS_(GNC_TLM|PLANT_TRUTH|EVENTS|CMD_ACK|GROUND_CMD|TRAJ_UPLINK)'
((log_all)) && channels='.*'
clock=$mode; [[ "$mode" == lockstep ]] || clock=realtime

export PIL_FSW="$fsw" PIL_PLANT="$plant" PIL_CASE="$case_arg" PIL_LAW="$law" PIL_LOG="$log"
export PIL_CHANNELS="$channels" PIL_OUT="$out" PIL_NAME="$name" PIL_TLM="$tlm_every"
export PIL_MODE="$mode" PIL_CLOCK="$clock" PIL_DURATION="$duration" PIL_KEY="$key"
export PIL_URL="udpm://239.255.76.67:$port?ttl=0" PIL_LOG_URL="udpm://239.255.76.67:$port?ttl=0"
PIL_BUSES=""
if ((!one_bus && !log_all)) && [[ "$mode" == lockstep ]]; then
  PIL_LOG_URL="udpm://239.255.76.67:$((port + 2))?ttl=0"
  PIL_BUSES="--actuator-lcm-url udpm://239.255.76.67:$((port + 1))?ttl=0 --ground-lcm-url $PIL_LOG_URL --direct-rx"
fi
export PIL_BUSES

echo "== PIL: $name, law $law, $mode; plant + fsw + lcm-logger in a private network namespace =="
rc=0
unshare -rn bash -c '
  set -u
  ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo
  lcm-logger -q --lcm-url="$PIL_LOG_URL" --channel="$PIL_CHANNELS" -f "$PIL_LOG" > /dev/null 2>&1 & logger=$!
  "$PIL_FSW" --lcm-url "$PIL_URL" --case "$PIL_CASE" --law "$PIL_LAW" --clock "$PIL_CLOCK" \
      --key-file "$PIL_KEY" --start-mode DETUMBLE --tlm-every "$PIL_TLM" -v $PIL_BUSES > "$PIL_OUT/$PIL_NAME.fsw.log" 2>&1 & fsw=$!
  trap "kill $fsw $logger 2>/dev/null" EXIT
  sleep 0.5   # the logger and the flight software subscribe; the plant waits for frame 0 anyway
  dur=(); [[ -n "$PIL_DURATION" ]] && dur=(--duration "$PIL_DURATION")
  "$PIL_PLANT" --lcm-url "$PIL_URL" --case "$PIL_CASE" --mode "$PIL_MODE" --summary \
      --truth-every "$PIL_TLM" --out "$PIL_OUT/$PIL_NAME.csv" "${dur[@]}" $PIL_BUSES 2> "$PIL_OUT/$PIL_NAME.plant.err"
  rc=$?
  sleep 0.3   # the last telemetry reaches the log
  kill -INT $fsw $logger 2>/dev/null; wait $fsw $logger 2>/dev/null
  trap - EXIT
  exit $rc
' || rc=$?
echo
if ((rc != 0)); then
  # The reason is in the children's output: show it here rather than leave it in a file.
  echo "pil.sh: the run failed (exit $rc). The plant said:" >&2
  tail -n 15 "$out/$name.plant.err" 2>/dev/null | sed 's/^/  plant: /' >&2
  echo "The flight software's last lines ($out/$name.fsw.log):" >&2
  tail -n 15 "$out/$name.fsw.log" 2>/dev/null | sed 's/^/  fsw: /' >&2
  exit 1
fi
echo "LCM log:      $log ($(du -h "$log" | cut -f1)); flight software log: $out/$name.fsw.log; time series: $out/$name.csv"
echo "Replay it:    lcm-logplayer -s 10 $log   (with ground/spy/rocksteady-spy running, see fsw/main/README.md)"
echo "Plot it:      $build/ground/cli/rocksteady-ground plot $log"
echo "Command key:  $key (the flight's; ground tools: rocksteady-ground --key-file $key send ...)"
exit 0
