#!/usr/bin/env bash
# Installs the Debian packages named on the command line that are not yet
# installed, and what they need. apt's plan is simulated first and every
# installed package it would upgrade is named before anything happens: a
# -dev package needs its library at its own version (libsystemd-dev pins
# libsystemd0), so on a base image older than the archive's point release
# the set-up cannot succeed without that upgrade. Nothing else is upgraded.
# Does nothing (and needs no network) when all are present.
# INSTALL_DEPS_DRY_RUN=1: report the plan, install nothing.
# INSTALL_DEPS_NO_UPGRADE=1: refuse a plan that upgrades an installed package
#   (a machine whose upgrades are the administrator's decision).
set -euo pipefail
missing=()
for pkg in "$@"; do
  status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$pkg")
done
[[ ${#missing[@]} -eq 0 ]] && exit 0
echo "install-deps: missing Debian packages: ${missing[*]}"
if [[ $(id -u) -ne 0 ]]; then
  echo "install-deps: need root to install ${missing[*]} (or install them yourself)" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
apt_install=(apt-get install -y -qq --no-upgrade --no-install-recommends)
apt-get update -qq
# Simulated: "Inst <package> [<installed version>] (<new version> ...)" is an upgrade.
plan=$("${apt_install[@]}" --simulate "${missing[@]}")
upgrades=$(sed -n 's/^Inst \([^ ]*\) \[\([^]]*\)\] (\([^ ]*\).*/\1 \2 -> \3/p' <<<"$plan")
if [[ -n $upgrades ]]; then
  echo "install-deps: installing ${missing[*]} upgrades installed packages they need:" >&2
  sed 's/^/  /' <<<"$upgrades" >&2
  if [[ -n ${INSTALL_DEPS_NO_UPGRADE:-} ]]; then
    echo "install-deps: INSTALL_DEPS_NO_UPGRADE is set: not upgrading anything; upgrade them yourself (apt-get install ${missing[*]}) and rerun" >&2
    exit 1
  fi
fi
if [[ -n ${INSTALL_DEPS_DRY_RUN:-} ]]; then
  echo "install-deps: dry run: would install: $(sed -n 's/^Inst \([^ ]*\) .*/\1/p' <<<"$plan" | tr '\n' ' ')"
  exit 0
fi
"${apt_install[@]}" "${missing[@]}"
