#!/usr/bin/env bash
# ctest packaging.install_prefix: `make install` (cmake --install) under
# /usr/local, as a user would without a PREFIX, into a scratch DESTDIR: the
# installed unit runs the daemon where it was installed and documents itself
# with the README installed beside it.
# Usage: install_prefix_test.sh BUILD_DIR VERSION (unit_checks.sh reads them)
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=unit_checks.sh
source "$here/unit_checks.sh"
root=$scratch

DESTDIR=$root cmake --install "$build" --prefix /usr/local >/dev/null
check_installed_unit /usr/local/lib/systemd/system/cdpr-calibd.service /usr/local
check_version /usr/local/sbin/cdpr-calibd "$version"
for program in calibctl cdpr-calib cdpr-sim cdpr-accuracy virtual-robot; do
  check_version "/usr/local/bin/$program" "$version"
done
for file in lib/sysusers.d/cdpr-calib.conf lib/tmpfiles.d/cdpr-calib.conf \
            share/doc/cdpr-calibration/examples/cdpr-calibd.toml \
            share/cdpr-calibration/eds/maxon-epos4.eds share/cdpr-calibration/eds/kuebler-sendix.eds; do
  [[ -f $root/usr/local/$file ]] || fail "/usr/local/$file was not installed"
done
echo "install under /usr/local: unit, binaries, docs agree"
