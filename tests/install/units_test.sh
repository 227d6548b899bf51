#!/usr/bin/env bash
# install.units (ctest): `systemd-analyze verify` on packaging/systemd/*.service as committed,
# with only their /usr/bin/ paths pointed at this build tree's binaries (verify checks that
# ExecStart is executable; the .debs are not needed). Any diagnostic fails: verify itself exits
# 0 on unknown keys and bad values. install.debs verifies the units as packaged, in a root.
#   units_test.sh --source SRC --build BLD
set -euo pipefail
src=$2 bld=$4
command -v systemd-analyze >/dev/null || { echo "no systemd-analyze (apt-get install systemd)"; exit 77; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
units=()
for u in edmplc edmhmi; do
  sed "s|/usr/bin/|$bld/bin/|g" "$src/packaging/systemd/$u.service" >"$tmp/$u.service"
  units+=("$tmp/$u.service")
done
if out=$(systemd-analyze verify "${units[@]}" 2>&1) && [ -z "$out" ]; then
  echo "systemd-analyze verify: edmplc.service, edmhmi.service: no diagnostic"
  systemd-analyze --version | head -1
else
  echo "systemd-analyze verify:"; echo "$out"; exit 1
fi
