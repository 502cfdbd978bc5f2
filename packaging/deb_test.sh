#!/usr/bin/env bash
# ctest packaging.deb: make deb, lintian finds no errors, and the package
# unpacked into a scratch root (dpkg -x: dpkg -i --root would need the
# whole dependency closure inside it) holds what the unit and Debian
# expect; its postinst, run as dpkg runs it for another root (DPKG_ROOT),
# creates the service user and the state and runtime directories.
# Usage: deb_test.sh BUILD_DIR VERSION (unit_checks.sh reads them)
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=unit_checks.sh
source "$here/unit_checks.sh"

deb=$("$here/../tools/make-deb.sh" "$build" "$version")
echo "== lintian $deb"
lintian --fail-on error "$deb" || fail "lintian reports errors"

root=$scratch/tree
dpkg -x "$deb" "$root"
dpkg -e "$deb" "$scratch/control"
grep -qx /etc/cdpr-calib/cdpr-calibd.toml "$scratch/control/conffiles" || fail "the configuration is not a conffile"
for file in usr/sbin/cdpr-calibd usr/bin/calibctl usr/bin/cdpr-calib usr/bin/cdpr-sim usr/bin/cdpr-accuracy \
            usr/bin/virtual-robot usr/lib/sysusers.d/cdpr-calib.conf usr/lib/tmpfiles.d/cdpr-calib.conf \
            etc/cdpr-calib/cdpr-calibd.toml usr/share/doc/cdpr-calibration/README.md \
            usr/share/doc/cdpr-calibration/copyright usr/share/doc/cdpr-calibration/changelog.Debian.gz; do
  [[ -f $root/$file ]] || fail "the package has no /$file"
done
cmp "$here/../systemd/cdpr-calibd.service" "$root/usr/lib/systemd/system/cdpr-calibd.service" ||
  fail "the packaged unit differs from systemd/cdpr-calibd.service"
check_installed_unit /usr/lib/systemd/system/cdpr-calibd.service /usr
check_version /usr/sbin/cdpr-calibd "$version"

DPKG_ROOT=$root sh "$scratch/control/postinst" configure
grep -q '^cdpr-calib:' "$root/etc/passwd" || fail "postinst created no user cdpr-calib"
for dir in var/lib/cdpr-calib/history run/cdpr-calib; do
  [[ -d $root/$dir ]] || fail "postinst created no /$dir"
done
echo "package $(basename "$deb"): files, conffile, unit, postinst as expected"
