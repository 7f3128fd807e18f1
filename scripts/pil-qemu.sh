#!/usr/bin/env bash
# Processor-in-the-loop on an emulated board: the aarch64 cross-built rocksteady-fsw runs under
# qemu-aarch64 (user mode) and closes the loop over LCM with the native rocksteady-plant, in lockstep,
# inside a private network namespace (unshare -rn: no root, no network touched). The same case is
# then flown with the native rocksteady-fsw, and the plant's figures of merit (SPEC §7, computed on
# the true state) of the two runs are compared, bit for bit by default.
#
# Usage: scripts/pil-qemu.sh [options]
#   --fast             the shortened case 1 of tests/pil (PilLockstep.*: u_max 2000 N, NTCL K = 1e6,
#                      Lambda = 3e-2, 600 s simulated = 6000 periods), generated from configs/ by
#                      the same line replacements; default: configs/cases/case1.yaml as it is
#   --duration S       simulated seconds (default: the case's)
#   --native DIR       native build with rocksteady-fsw and rocksteady-plant (default build/release)
#   --cross DIR        aarch64 build with rocksteady-fsw (default build/aarch64)
#   --out DIR          output folder (default out/pil-qemu): case files, logs, summaries
#   --tolerance REL    accept relative differences up to REL in the numeric figures (default 0:
#                      bit for bit, which is what the builds deliver, see the note below)
#   --timeout S        wall-clock bound of each run (default 900)
#   --skip-native      fly only the emulated board (no comparison)
# Exit status: 0 when both runs finish without held periods and the figures match, 1 otherwise,
# 2 on usage or missing programs.
#
# Bit for bit: the flight side is compiled without floating-point contraction on aarch64
# (-ffp-contract=off, cmake/toolchains/aarch64-linux-gnu.cmake), as x86-64 without FMA computes;
# GCC's aarch64 default (fast: a*b+c fused into one FMA) changes the last bits of the control law.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
self="$here/scripts/$(basename "$0")"
cd "$here"

fast=0 duration="" native=build/release cross=build/aarch64 out=out/pil-qemu tol=0 tmo=900
skip_native=0
args=("$@")
while (($#)); do
  case "$1" in
    --fast) fast=1; shift ;;
    --duration) duration="$2"; shift 2 ;;
    --native) native="$2"; shift 2 ;;
    --cross) cross="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --tolerance) tol="$2"; shift 2 ;;
    --timeout) tmo="$2"; shift 2 ;;
    --skip-native) skip_native=1; shift ;;
    -h|--help) sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "pil-qemu.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done

# Outside the namespace: check the programs, then re-execute inside a private network namespace.
if [[ -z "${ROCKSTEADY_PIL_QEMU_NS:-}" ]]; then
  fsw_native="$native/fsw/main/rocksteady-fsw"
  plant="$native/ground/plantd/rocksteady-plant"
  fsw_cross="$cross/fsw/main/rocksteady-fsw"
  need=("$plant" "$fsw_cross")
  ((skip_native)) || need+=("$fsw_native")
  for p in "${need[@]}"; do
    [[ -x "$p" ]] || { echo "pil-qemu.sh: $p not found: build it first" >&2; exit 2; }
  done
  command -v qemu-aarch64 >/dev/null || { echo "pil-qemu.sh: qemu-aarch64 not found (qemu-user)" >&2; exit 2; }
  command -v unshare >/dev/null || { echo "pil-qemu.sh: unshare not found (util-linux)" >&2; exit 2; }
  exec unshare -rn env ROCKSTEADY_PIL_QEMU_NS=1 "$self" "${args[@]}"
fi

# Inside the namespace: loopback up, the LCM multicast group routed to it.
ip link set lo up && ip link set lo multicast on && ip route add 239.255.76.67 dev lo
unset QEMU_LD_PREFIX  # multiarch loader and libraries at their normal paths (ENVIRONMENT notes)

fsw_native="$native/fsw/main/rocksteady-fsw"
plant="$native/ground/plantd/rocksteady-plant"
fsw_cross="$cross/fsw/main/rocksteady-fsw"
# LCM and yaml-cpp of the board build come from its private sysroot (cmake/toolchains/arm64-sysroot.sh).
sysroot=$(sed -n 's/^ROCKSTEADY_TARGET_SYSROOT:[A-Z]*=//p' "$cross/CMakeCache.txt" 2>/dev/null || true)
[[ -n "$sysroot" ]] || sysroot="$cross/sysroot"
qemu=(qemu-aarch64 -E "LD_LIBRARY_PATH=$sysroot/usr/lib/aarch64-linux-gnu")

mkdir -p "$out"
mission=configs/mission.yaml gnc=configs/gnc.yaml case_file=configs/cases/case1.yaml
if ((fast)); then
  # The same whole-line replacements as tests/pil's make_fast_case().
  gnc="$out/gnc_fast.yaml" case_file="$out/case1_fast.yaml"
  sed 's/^  ntcl:.*/  ntcl:        {K: 1.0e6, Lambda: 3.0e-2}/' configs/gnc.yaml > "$gnc"
  sed -e 's/^u_max_n:.*/u_max_n: 2000/' -e 's/^duration_s:.*/duration_s: 600/' \
      configs/cases/case1.yaml > "$case_file"
  grep -q '^  ntcl:        {K: 1.0e6' "$gnc" && grep -q '^u_max_n: 2000' "$case_file" &&
    grep -q '^duration_s: 600' "$case_file" || { echo "pil-qemu.sh: fast case not generated" >&2; exit 2; }
fi
dur=(); [[ -n "$duration" ]] && dur=(--duration "$duration")

# One lockstep run: fsw (argv prefix given) + native plant on their own port; the plant's summary
# line goes to $out/<name>.summary.
run() {
  local name=$1 port=$2; shift 2
  local url="udpm://239.255.76.67:$port?ttl=0"
  "$@" --lcm-url "$url" --mission "$mission" --gnc "$gnc" --case "$case_file" --law ntcl \
      --clock lockstep --lab-mode --start-mode DETUMBLE --tlm-every 10 > "$out/$name.fsw.log" 2>&1 &
  local fsw=$!
  local rc=0
  # Generous echo timeout: an emulated tick can take a while; a resend is harmless (the fsw answers
  # a repeated frame with the command it already computed), a held period is counted and fails.
  timeout "$tmo" "$plant" --lcm-url "$url" --mission "$mission" --gnc "$gnc" --case "$case_file" \
      --summary --truth-every 10 --timeout-ms 500 --retries 100 --startup-timeout 60 "${dur[@]}" \
      > "$out/$name.plant.log" 2>&1 || rc=$?
  kill -INT "$fsw" 2>/dev/null || true
  wait "$fsw" 2>/dev/null || true
  grep '^summary: ' "$out/$name.plant.log" | sed 's/^summary: //' > "$out/$name.summary" || true
  if ((rc != 0)) || [[ ! -s "$out/$name.summary" ]]; then
    echo "pil-qemu.sh: $name run failed (plant exit $rc)" >&2
    tail -n 20 "$out/$name.plant.log" "$out/$name.fsw.log" >&2
    return 1
  fi
  grep ' over LCM ' "$out/$name.plant.log" | sed "s/^/  $name: /"
}

status=0
echo "== PIL on an emulated board: qemu-aarch64 rocksteady-fsw + native rocksteady-plant, lockstep, $(basename "$case_file" .yaml) =="
run qemu 7701 "${qemu[@]}" "$fsw_cross" || exit 1
if ((skip_native)); then
  cat "$out/qemu.summary"
  exit 0
fi
run native 7702 "$fsw_native" || exit 1

# Figures of merit: exact strings (%.17g) unless a tolerance is given; NC must match NC.
awk -v tol="$tol" '
  function kv(line, arr,   n, i, f, p) {
    n = split(line, f, " ")
    for (i = 1; i <= n; i++) { p = index(f[i], "="); arr[substr(f[i], 1, p - 1)] = substr(f[i], p + 1) }
  }
  NR == 1 { kv($0, q) } NR == 2 { kv($0, nat) }
  END {
    split("periods t_omega fuel_omega t_q fuel_q total_fuel final_rate final_q_error flight_mode", keys, " ")
    bad = 0
    printf "  %-14s %-24s %-24s %s\n", "figure", "qemu-aarch64 fsw", "native fsw", "verdict"
    for (i = 1; i in keys; i++) {
      k = keys[i]; a = q[k]; b = nat[k]
      if (a == b) verdict = "identical"
      else if (tol > 0 && a ~ /^[-+0-9.eE]+$/ && b ~ /^[-+0-9.eE]+$/ &&
               (a - b <= tol * (b < 0 ? -b : b) && b - a <= tol * (b < 0 ? -b : b))) {
        d = (b != 0) ? (a - b) / b : a - b
        verdict = sprintf("within %g (rel %.3g)", tol, d)
      } else { verdict = "DIFFERENT"; bad = 1 }
      printf "  %-14s %-24s %-24s %s\n", k, a, b, verdict
    }
    for (w in q) if (w == "holds" && (q[w] != "0" || nat[w] != "0")) {
      printf "  held periods: qemu %s native %s (must be 0)\n", q[w], nat[w]; bad = 1
    }
    exit bad
  }' "$out/qemu.summary" "$out/native.summary" || status=1
for r in qemu native; do
  sed -n 's/.*periods=\([0-9]*\).*resends=\([0-9]*\) holds=\([0-9]*\).*wall_s=\([0-9.]*\).*/\1 \2 \3 \4/p' \
      "$out/$r.summary" | awk -v r="$r" '{ printf "  %-6s %s periods in %.2f s wall: %.0f periods/s (resends %s, holds %s)\n", r, $1, $4, $1 / $4, $2, $3 }'
done
if ((status)); then
  echo "pil-qemu.sh: FAIL: the emulated board's figures of merit differ from the native flight software's" >&2
else
  echo "pil-qemu.sh: the emulated board's figures of merit match the native flight software's"
fi
exit $status
