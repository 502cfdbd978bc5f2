#!/usr/bin/env bash
# ctest tools.install_deps: tools/install-deps.sh against stub dpkg-query,
# apt-get and id (first on PATH) that record their calls: nothing happens
# when all is installed, only the missing packages are installed (with
# --no-upgrade), an apt plan that upgrades an installed dependency names it
# and goes on, and with INSTALL_DEPS_NO_UPGRADE it names it and installs
# nothing.
set -euo pipefail
script=$(cd "$(dirname "$0")/../.." && pwd)/tools/install-deps.sh
stubs=$(mktemp -d /tmp/cdpr-install-deps.XXXXXX)
trap 'rm -rf "$stubs"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

cat >"$stubs/dpkg-query" <<'STUB'
#!/bin/sh
# dpkg-query -W -f='${Status}' PACKAGE, from $STUBS/installed ("package status")
pkg=$(eval echo \${$#})
line=$(grep "^$pkg " "$STUBS/installed") || exit 1
printf '%s' "${line#* }"
STUB
cat >"$stubs/apt-get" <<'STUB'
#!/bin/sh
echo "apt-get $*" >>"$STUBS/calls"
case " $* " in *" --simulate "*) cat "$STUBS/plan" ;; esac
STUB
printf '#!/bin/sh\necho 0\n' >"$stubs/id"
chmod +x "$stubs"/*
export STUBS=$stubs PATH=$stubs:$PATH

run() {  # installed-list plan args...; leaves output in $stubs/out and the exit status in $status
  printf '%b' "$1" >"$stubs/installed"
  printf '%b' "$2" >"$stubs/plan"
  : >"$stubs/calls"
  shift 2
  status=0
  "$script" "$@" >"$stubs/out" 2>&1 || status=$?
}

# All installed: no apt-get at all.
run 'cmake install ok installed\nlibfoo-dev install ok installed\n' '' cmake libfoo-dev
[[ $status -eq 0 && ! -s $stubs/calls ]] || fail "all installed: status $status, calls: $(cat "$stubs/calls")"

# One missing, one removed with its configuration left: only those two, with --no-upgrade.
run 'cmake install ok installed\nlibbar-dev deinstall ok config-files\n' \
    'Inst libfoo-dev (1.0 Debian:12 [amd64])\nInst libbar-dev (2.0 Debian:12 [amd64])\n' cmake libfoo-dev libbar-dev
[[ $status -eq 0 ]] || fail "missing packages: status $status: $(cat "$stubs/out")"
install=$(grep -v -e update -e --simulate "$stubs/calls")
[[ $install == *"--no-upgrade"* && $install == *" libfoo-dev libbar-dev" && $install != *cmake* ]] ||
  fail "missing packages: installed with '$install'"

# A plan that upgrades an installed dependency: the upgrade named, then installed.
upgrade_plan='Inst libsystemd0 [252.19-1~deb12u1] (252.39-1~deb12u2 Debian-Security:12 [amd64])\nInst libsystemd-dev (252.39-1~deb12u2 Debian-Security:12 [amd64])\n'
run 'systemd install ok installed\n' "$upgrade_plan" libsystemd-dev
[[ $status -eq 0 ]] || fail "upgrade plan: status $status: $(cat "$stubs/out")"
grep -q 'libsystemd0 252.19-1~deb12u1 -> 252.39-1~deb12u2' "$stubs/out" || fail "upgrade plan: not named: $(cat "$stubs/out")"
grep -v -e update -e --simulate "$stubs/calls" | grep -q ' libsystemd-dev$' || fail "upgrade plan: not installed"

# The same plan with INSTALL_DEPS_NO_UPGRADE: named, nothing installed.
INSTALL_DEPS_NO_UPGRADE=1 run 'systemd install ok installed\n' "$upgrade_plan" libsystemd-dev
[[ $status -ne 0 ]] || fail "no-upgrade plan: exit 0"
grep -q 'libsystemd0 252.19-1~deb12u1 -> 252.39-1~deb12u2' "$stubs/out" || fail "no-upgrade plan: not named: $(cat "$stubs/out")"
! grep -v -e update -e --simulate "$stubs/calls" | grep -q install || fail "no-upgrade plan: installed anyway"

# Dry run: the plan, nothing installed.
export INSTALL_DEPS_DRY_RUN=1
run '' 'Inst libfoo-dev (1.0 Debian:12 [amd64])\n' libfoo-dev
[[ $status -eq 0 ]] || fail "dry run failed: $(cat "$stubs/out")"
grep -q 'would install: libfoo-dev' "$stubs/out" || fail "dry run: $(cat "$stubs/out")"
! grep -v -e update -e --simulate "$stubs/calls" | grep -q install || fail "dry run: installed anyway"
echo "install-deps: only missing packages, upgrades named (refused with INSTALL_DEPS_NO_UPGRADE)"
