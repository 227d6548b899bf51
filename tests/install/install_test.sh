#!/usr/bin/env bash
# install.debs (ctest): the .debs installed into a clean root, checked from the installed tree.
#   install_test.sh --source SRC --build BLD --cpack CPACK
# The packages are $EDM_PACKAGE_DIR's (./edm test packs them into out/package first; they must
# be newer than the build's binaries), else this packs the build tree itself into a temp dir.
# The root is dpkg's own (`dpkg --root R --unpack`: its database, the two packages' file lists,
# no file of one package in the other) without a libc or a shell in it: the installed binaries
# run with the host's libraries, and dpkg runs no maintainer script (they would run in R,
# chrooted): they are syntax-checked, and edmplc's postinst runs with stand-in commands. As a
# non-root user dpkg runs under fakeroot.
set -euo pipefail

src="" bld="" cpack=""
while [ $# -gt 0 ]; do
  case "$1" in
    --source) src=$2; shift 2 ;;
    --build) bld=$2; shift 2 ;;
    --cpack) cpack=$2; shift 2 ;;
    *) echo "usage: $0 --source SRC --build BLD --cpack CPACK" >&2; exit 2 ;;
  esac
done
[ -n "$src" ] && [ -n "$bld" ] && [ -n "$cpack" ] || { echo "missing argument" >&2; exit 2; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
ok() { printf 'ok    %s\n' "$*"; }
fail() { printf 'FAIL  %s\n' "$*"; fails=$((fails + 1)); }

# 1. The packages.
if [ -n "${EDM_PACKAGE_DIR:-}" ]; then
  pkgdir=$EDM_PACKAGE_DIR
  for b in edmplc edmhmi; do
    deb=$(ls "$pkgdir"/${b}_*.deb 2>/dev/null | head -1)
    if [ -z "$deb" ]; then echo "no ${b}_*.deb in $pkgdir (./edm package)"; exit 1; fi
    if [ "$bld/bin/$b" -nt "$deb" ]; then
      echo "$deb is older than $bld/bin/$b: run ./edm package"; exit 1
    fi
  done
else
  pkgdir=$tmp/pkg
  "$cpack" --config "$bld/CPackConfig.cmake" -B "$pkgdir" >"$tmp/cpack.log" 2>&1 \
    || { cat "$tmp/cpack.log"; echo "cpack failed"; exit 1; }
fi
debs=("$pkgdir"/edmplc_*.deb "$pkgdir"/edmhmi_*.deb)
for d in "${debs[@]}"; do
  [ -f "$d" ] || { echo "missing: $d"; exit 1; }
  ok "package $(basename "$d"): $(dpkg-deb -f "$d" Depends)"
done

# 2. A clean root with an empty dpkg database; unpack only (no maintainer script runs).
R=$tmp/root
mkdir -p "$R/var/lib/dpkg/info" "$R/var/lib/dpkg/updates"
: >"$R/var/lib/dpkg/status"
runner=() extra=()
if [ "$(id -u)" -ne 0 ]; then runner=(fakeroot); extra=(--force-not-root); fi
if "${runner[@]}" dpkg --root="$R" --log=/dev/null --force-depends "${extra[@]}" \
    --unpack "${debs[@]}" >"$tmp/dpkg.log" 2>&1; then
  ok "dpkg --root R --unpack: $(dpkg --root="$R" -l 'edm*' | awk '/^.U/{print $2 " " $3}' | xargs)"
else
  cat "$tmp/dpkg.log"; fail "dpkg --root R --unpack"
fi
for f in edmplc:/usr/bin/edmplc edmplc:/usr/share/edmplc/machines/drill-sim.yaml \
    edmplc:/usr/share/edmplc/machines/fragments/drill-job-wiring.yaml \
    edmplc:/usr/lib/systemd/system/edmplc.service edmplc:/usr/share/doc/edmplc/deploy.md \
    edmplc:/usr/lib/udev/rules.d/60-edmplc.rules edmhmi:/usr/bin/edmhmi \
    edmhmi:/usr/share/edmplc/web/index.html edmhmi:/usr/lib/systemd/system/edmhmi.service; do
  pkg=${f%%:*} path=${f#*:}
  if dpkg --root="$R" -L "$pkg" 2>/dev/null | grep -qx "$path" && [ -e "$R$path" ]; then
    ok "$pkg ships $path"
  else
    fail "$pkg does not ship $path"
  fi
done

# 3. From the installed tree: the check of the issue, then every shipped machine.
if out=$("$R/usr/bin/edmplc" --config "$R/usr/share/edmplc/machines/drill-sim.yaml" --check 2>&1); then
  ok "installed edmplc --check: $out"
else
  fail "installed edmplc --check: $out"
fi
for c in "$R"/usr/share/edmplc/machines/*.yaml; do
  "$R/usr/bin/edmplc" --config "$c" --check >/dev/null 2>"$tmp/err" || fail "--check $(basename "$c"): $(cat "$tmp/err")"
done
ok "installed edmplc --check on $(ls "$R"/usr/share/edmplc/machines/*.yaml | wc -l) shipped machines"

# edmhmi finds its data beside itself (../share/edmplc), not in the build tree.
if out=$(env -u EDM_DATA_DIR "$R/usr/bin/edmhmi" check "$src/examples/parts/demo.nc" 2>&1) &&
    grep -qF "machine $R/usr/share/edmplc/machines/drill-sim.yaml" <<<"$out"; then
  ok "installed edmhmi check, default machine from the install prefix"
else
  fail "installed edmhmi check: $out"
fi
# serve refuses a missing page before it contacts edmplc: the page must be found, and
# $EDM_DATA_DIR must win over the install prefix. With the page found, serve listens and waits for
# edmplc (none at port 1) until it is stopped: timeout ends it.
out=$(env -u EDM_DATA_DIR timeout 5 "$R/usr/bin/edmhmi" --port 1 serve --listen 127.0.0.1:0 2>&1 || true)
if grep -q "index.html missing" <<<"$out" || ! grep -q "listening on" <<<"$out"; then
  fail "installed edmhmi serve: $out"
else
  ok "installed edmhmi serve finds the page in the install prefix"
fi
out=$(EDM_DATA_DIR=$tmp/none timeout 5 "$R/usr/bin/edmhmi" --port 1 serve --listen 127.0.0.1:0 2>&1 || true)
if grep -qF "$tmp/none/web/index.html missing" <<<"$out"; then
  ok "\$EDM_DATA_DIR overrides the install prefix"
else
  fail "EDM_DATA_DIR ignored: $out"
fi

# 4. No compiled-in path of the source or build tree in the shipped binaries (stripped).
for b in edmplc edmhmi; do
  hits=$(strings "$R/usr/bin/$b" | grep -F -e "$src" -e "$bld" | head -5 || true)
  if [ -z "$hits" ]; then ok "no $src or $bld path in /usr/bin/$b"; else fail "paths in /usr/bin/$b: $hits"; fi
done

# 5. The maintainer scripts parse; the packaged units verify in the root.
for d in "${debs[@]}"; do
  dpkg-deb -e "$d" "$tmp/ctl-$(basename "$d")"
  for s in "$tmp/ctl-$(basename "$d")"/{postinst,prerm,postrm}; do
    sh -n "$s" || fail "sh -n $(basename "$d") $(basename "$s")"
  done
done
ok "maintainer scripts parse (sh -n)"
# edmplc's postinst with stand-ins for getent, adduser and udevadm that log their arguments (no
# user is made on this host): "configure" on a host without the user must make it, once.
stubs=$tmp/stubs
mkdir -p "$stubs"
for c in getent adduser udevadm systemctl; do
  printf '#!/bin/sh\necho "%s $*" >>"%s/calls"\n[ %s != getent ]\n' "$c" "$stubs" "$c" >"$stubs/$c"
  chmod +x "$stubs/$c"
done
ctl=$tmp/ctl-$(basename "${debs[0]}")
if PATH=$stubs:/usr/bin:/bin sh "$ctl/postinst" configure &&
    grep -qx "adduser --system --group --home /var/lib/edmplc --no-create-home --gecos edmplc runtime edmplc" \
      "$stubs/calls"; then
  ok "edmplc postinst configure: $(grep adduser "$stubs/calls")"
else
  fail "edmplc postinst: $(cat "$stubs/calls" 2>/dev/null)"
fi
if command -v systemd-analyze >/dev/null; then
  # systemd-analyze --root reads every unit from R: the host's units (targets, slices) are
  # copied in beside the packaged ones, which it reads as shipped (ExecStart: R/usr/bin/...).
  mkdir -p "$R/lib/systemd"
  cp -a /lib/systemd/system "$R/lib/systemd/"
  out=$(systemd-analyze verify --root="$R" /usr/lib/systemd/system/edmplc.service \
    /usr/lib/systemd/system/edmhmi.service 2>&1) && [ -z "$out" ] &&
    ok "systemd-analyze verify --root R: the packaged edmplc.service, edmhmi.service" ||
    fail "systemd-analyze verify --root R: $out"
else
  echo "note  no systemd-analyze: the packaged units are not verified here (install.units)"
fi

[ "$fails" -eq 0 ] || { echo "$fails check(s) failed"; exit 1; }
echo "install test passed"
