#!/usr/bin/env bash
# make deb: the Debian binary package cdpr-calibration from an existing build,
# with dpkg-deb from a staged tree (packaging/deb/ holds the control files):
#   /usr/sbin/cdpr-calibd (where the unit's ExecStart= looks), /usr/bin/...,
#   the unit, sysusers.d and tmpfiles.d files, /etc/cdpr-calib/cdpr-calibd.toml
#   (a conffile: the example configuration), /usr/share/doc/cdpr-calibration
#   (README.md, the example, copyright, changelog.Debian.gz).
# Binaries stripped, Depends from dpkg-shlibdeps, files owned by root.
# Usage: tools/make-deb.sh BUILD_DIR VERSION; prints the .deb's path.
set -euo pipefail
build=$(cd "$1" && pwd)
version=$2
source=$(cd "$(dirname "$0")/.." && pwd)
control=$source/packaging/deb
package=cdpr-calibration

# The Debian version is the changelog's; its upstream part must be the project's.
debian_version=$(sed -n '1s/^[^(]*(\([^)]*\)).*/\1/p' "$control/changelog")
if [[ ${debian_version%-*} != "$version" ]]; then
  echo "make-deb: packaging/deb/changelog is at $debian_version, the project at $version: add a changelog entry" >&2
  exit 1
fi
arch=$(dpkg --print-architecture)

stage=$build/deb/stage
rm -rf "$build/deb"
mkdir -p "$stage/DEBIAN"
DESTDIR=$stage cmake --install "$build" --prefix /usr --strip >/dev/null
install -D -m 0644 "$source/systemd/cdpr-calibd.toml" "$stage/etc/cdpr-calib/cdpr-calibd.toml"
doc=$stage/usr/share/doc/$package
install -m 0644 "$control/copyright" "$doc/copyright"
gzip -9n <"$control/changelog" >"$doc/changelog.Debian.gz"
chmod -R u=rwX,go=rX "$stage"
chmod 0755 "$stage"/usr/bin/* "$stage"/usr/sbin/*

# Shared-library dependencies, as dh_shlibdeps finds them.
shlibs=$build/deb/shlibs
mkdir -p "$shlibs/debian"
printf 'Source: %s\n\nPackage: %s\nArchitecture: any\n' "$package" "$package" >"$shlibs/debian/control"
depends=$(cd "$shlibs" && dpkg-shlibdeps -O "$stage"/usr/bin/* "$stage"/usr/sbin/* 2>/dev/null |
          sed -n 's/^shlibs:Depends=//p')

installed_kb=$(du -sk --exclude=DEBIAN "$stage" | cut -f1)
sed -e "s/@VERSION@/$debian_version/" -e "s/@ARCH@/$arch/" -e "s/@INSTALLED_SIZE@/$installed_kb/" \
    -e "s/@DEPENDS@/$depends/" "$control/control.in" >"$stage/DEBIAN/control"
install -m 0644 "$control/conffiles" "$stage/DEBIAN/conffiles"
install -m 0755 "$control/postinst" "$control/postrm" "$stage/DEBIAN/"
(cd "$stage" && find . -path ./DEBIAN -prune -o -type f -printf '%P\0' | sort -z | xargs -0 md5sum) \
  >"$stage/DEBIAN/md5sums"
chmod 0644 "$stage/DEBIAN/md5sums"

deb=$build/${package}_${debian_version}_${arch}.deb
dpkg-deb --root-owner-group -Zxz --build "$stage" "$deb" >/dev/null
echo "$deb"
