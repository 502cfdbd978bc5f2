# Sourced by the packaging tests (arguments BUILD_DIR VERSION): a scratch
# directory, and checks of an installed tree ($root). Each failure says
# what is wrong.

set -euo pipefail
fail() { echo "FAIL: $*" >&2; exit 1; }
build=$1 version=$2
# The scratch directory the test installs into, removed on exit.
scratch=$(mktemp -d /tmp/cdpr-packaging.XXXXXX)
trap 'rm -rf "$scratch"' EXIT

# The unit at $root$1, installed under prefix $2: ExecStart= and Documentation= point at files installed with the unit, and
# systemd-analyze verify accepts it with that binary in place (the scratch
# root gets the host's targets so that its dependencies resolve).
check_installed_unit() {
  local unit=$root$1 prefix=$2
  [[ -f $unit ]] || fail "no unit at $1"
  local exec doc
  exec=$(sed -n 's/^ExecStart=\([^ ]*\).*/\1/p' "$unit")
  [[ $exec == "$prefix/sbin/cdpr-calibd" ]] || fail "ExecStart= runs $exec, not $prefix/sbin/cdpr-calibd"
  [[ -x $root$exec ]] || fail "ExecStart= binary $exec was not installed"
  doc=$(sed -n 's/^Documentation=file:\(.*\)/\1/p' "$unit")
  [[ -f $root$doc ]] || fail "Documentation= names $doc, which was not installed"
  mkdir -p "$root/lib/systemd/system"
  cp /usr/lib/systemd/system/*.target "$root/lib/systemd/system/"
  systemd-analyze verify --root="$root" "$unit" || fail "systemd-analyze verify $1"
}

check_version() {
  local out
  out=$("$root$1" --version) || fail "$1 --version failed"
  [[ $out == "$(basename "$1") $2"* ]] || fail "$1 --version says '$out', not version $2"
}
