#!/usr/bin/env bash
# Keeps the change tour true: every path that docs/DESIGN.md and the
# folders' READMEs name in backquotes exists, and the layering claims the
# build cannot check hold (the build enforces which folder a target may
# include; these are finer):
#   - hal/ includes no OS, bus or project header from outside hal/;
#   - solver/ includes nothing of src/, drivers/, hal/ or tools/;
#   - in src/, only main.cc builds drivers; the daemon's configuration
#     holds the drivers' settings structs (the files listed below).
# Usage: design_tour_test.sh [SOURCE_DIR]. Prints every broken claim.
set -uo pipefail
cd "${1:-$(dirname "$0")/../..}" || exit 2
failures=0
fail() { echo "design tour: $*"; failures=$((failures + 1)); }

# A named path: `a/b.h/.cc` stands for a/b.h and a/b.cc, `a/b.{h,cc}` too;
# `*` globs must match something; a trailing / names a folder.
check_path() {
  local doc=$1 path=$2
  case $path in
    *'<'*) return ;;  # a placeholder such as tests/src/formats/<file>_test.cc
  esac
  if [[ $path =~ ^(.*)\.\{([a-z,]+)\}$ ]]; then
    local base=${BASH_REMATCH[1]} ext
    IFS=, read -ra exts <<<"${BASH_REMATCH[2]}"
    for ext in "${exts[@]}"; do check_path "$doc" "$base.$ext"; done
    return
  fi
  if [[ $path =~ ^(.*)\.([a-z]+)/\.([a-z]+)$ ]]; then
    local stem=${BASH_REMATCH[1]} first=${BASH_REMATCH[2]} second=${BASH_REMATCH[3]}
    check_path "$doc" "$stem.$first"
    check_path "$doc" "$stem.$second"
    return
  fi
  if [[ $path == *'*'* ]]; then
    compgen -G "$path" >/dev/null || fail "$doc names $path: nothing matches"
    return
  fi
  [[ -e $path ]] || fail "$doc names $path: no such file or folder"
}

# Paths relative to the repository in DESIGN.md; relative to their folder
# in a folder's README (solver/README.md says model/effects.h).
check_doc() {
  local doc=$1 prefix=$2 token
  while read -r token; do
    token=${token//\`/}
    case $token in
      solver/* | src/* | drivers/* | hal/* | tools/* | tests/* | systemd/* | docs/* | packaging/*) check_path "$doc" "$token" ;;
      */*)
        [[ -n $prefix && $token =~ ^[a-z_]+/[a-z_]+ && -d $prefix/${token%%/*} ]] && check_path "$doc" "$prefix/$token"
        ;;
    esac
  done < <(grep -o '`[A-Za-z0-9_./*{},<>-]*/[A-Za-z0-9_./*{},<>-]*`' "$doc" | sort -u)
}

check_doc docs/DESIGN.md ""
for folder in solver src drivers; do check_doc "$folder/README.md" "$folder"; done

includes() { grep -rn --include='*.h' --include='*.cc' -E "^#include [\"<]($2)" "$1"; }

while read -r line; do fail "hal/ includes outside hal: $line"; done < <(includes hal 'src/|drivers/|solver/|tools/|linux/|modbus|sys/|systemd/|gpiod')
while read -r line; do fail "solver/ includes outside solver: $line"; done < <(includes solver 'src/|drivers/|hal/|tools/')

# The daemon's configuration holds the drivers' own settings structs; the
# driver objects are chosen and built in main.cc alone.
config_holders="src/daemon/daemon_config.h src/daemon/device_config_tables.cc"
while read -r file; do
  [[ $file == src/main.cc || " $config_holders " == *" $file "* ]] && continue
  fail "$file includes a driver header; only src/main.cc and the configuration ($config_holders) may"
done < <(grep -rl --include='*.h' --include='*.cc' '^#include "drivers/' src | sort)

if ((failures > 0)); then
  echo "design tour: $failures broken claim(s): fix the doc or the code (docs/DESIGN.md)"
  exit 1
fi
echo "design tour: every named path exists and the layering claims hold"
