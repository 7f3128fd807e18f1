#!/usr/bin/env bash
# cmake --install puts every program, the configs, the types jar, the lcm-spy launcher and the
# console's web assets under the prefix, and an installed program finds its configs from any
# directory; cpack builds a .deb with the same files.
# Usage: install_test.sh BUILD_DIR SCRATCH_DIR
set -euo pipefail
build="$1"
scratch="$2"
rm -rf "$scratch"
mkdir -p "$scratch"
prefix="$scratch/prefix"
cmake --install "$build" --prefix "$prefix" >"$scratch/install.log"
fail=0
for f in bin/rocksteady-fsw bin/rocksteady-plant bin/rocksteady-campaign bin/rocksteady-ground \
         bin/rocksteady-plan share/rocksteady/configs/mission.yaml \
         share/rocksteady/configs/cases/case7.yaml share/rocksteady/java/rocksteady_types.jar \
         share/rocksteady/bin/rocksteady-spy share/rocksteady/console-web/app/index.html; do
  if [[ ! -e "$prefix/$f" ]]; then
    echo "missing after install: $f"
    fail=1
  fi
done
# An installed tool finds its configs next to itself, from an unrelated directory.
(cd "$scratch" && env -u ROCKSTEADY_CONFIG_DIR "$prefix/bin/rocksteady-plan" --case 1 \
   -o "$scratch/plan.yaml" >"$scratch/plan.log" 2>&1) \
  || { echo "the installed planner does not find its configs"; cat "$scratch/plan.log"; fail=1; }
# The package.
(cd "$scratch" && cpack --config "$build/CPackConfig.cmake" -G DEB -B "$scratch/pkg" >"$scratch/cpack.log" 2>&1) \
  || { echo "cpack failed"; tail -20 "$scratch/cpack.log"; exit 1; }
deb=$(ls "$scratch"/pkg/*.deb | head -1)
contents=$(dpkg-deb -c "$deb")
for f in bin/rocksteady-fsw bin/rocksteady-plant bin/rocksteady-ground share/rocksteady/configs/gnc.yaml \
         share/rocksteady/java/rocksteady_types.jar; do
  if ! grep -q "$f" <<<"$contents"; then
    echo "missing in the .deb: $f"
    fail=1
  fi
done
echo "deb: $(basename "$deb"), $(stat -c %s "$deb") bytes"
exit $fail
