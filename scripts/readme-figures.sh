#!/usr/bin/env bash
# Regenerates the measured figures the README quotes, so none of them is typed by hand: each is
# written between its markers (<!-- figures:NAME:begin --> ... <!-- figures:NAME:end -->).
#   campaign   the study's table (7 cases x 6 strategies) on every core: closed-loop throughput
#   pil        study case 1 processor-in-the-loop (scripts/pil.sh): figures of merit, ticks/s
# and, with --all, the tables in fsw/main/README.md (tests/pil/bench.sh, scripts/jitter-bench.sh).
# Usage: scripts/readme-figures.sh [--build DIR] [--all]
set -euo pipefail
cd "$(dirname "$0")/.."
build=build/release all=0
while (($#)); do
  case "$1" in
    --build) build="$2"; shift 2 ;;
    --all) all=1; shift ;;
    -h|--help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "readme-figures.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Replace the text between a pair of markers in a file.
put() { scripts/put-block.py "$1" "figures:$2" "$3" > /dev/null; }

machine="$(nproc) cores, $(date -u +%Y-%m-%d)"

# 1. The campaign (planning excluded from the throughput).
"$build/ground/campaign/rocksteady-campaign" campaign --quiet --no-timeseries -o "$tmp/campaign" \
  > "$tmp/campaign.out" 2>&1
line=$(grep '^campaign:' "$tmp/campaign.out" | tail -1)
printf 'Measured by `scripts/readme-figures.sh` (%s): %s.\n' "$machine" "${line#campaign: }" \
  > "$tmp/campaign.md"
put README.md campaign "$tmp/campaign.md"

# 2. Case 1 processor-in-the-loop.
scripts/pil.sh 1 --out "$tmp/pil" > "$tmp/pil.out" 2>&1
summary=$(grep '^summary:' "$tmp/pil.out" | tail -1)
field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" <<<"$summary"; }
periods=$(field periods) wall=$(field wall_s)
python3 - "$periods" "$wall" "$(field t_omega)" "$(field t_q)" "$(field total_fuel)" "$machine" \
  > "$tmp/pil.md" <<'PY'
import sys
periods, wall, tw, tq, fuel, machine = sys.argv[1:]
rate = float(periods) / float(wall)
group = lambda x: f"{x:,.0f}".replace(",", " ")
print(f"Measured by `scripts/readme-figures.sh` ({machine}): t_ω,conv {float(tw):.1f} s, "
      f"t_q,conv {float(tq):.1f} s, total fuel {float(fuel):.3f} kg; {group(int(periods))} ticks in "
      f"{float(wall):.1f} s wall, {group(rate)} ticks/s over LCM.")
PY
put README.md pil "$tmp/pil.md"

if ((all)); then
  tests/pil/bench.sh --readme fsw/main/README.md
  scripts/jitter-bench.sh --readme fsw/main/README.md
fi
echo "readme-figures: README.md updated"
