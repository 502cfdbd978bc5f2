#!/usr/bin/env bash
# Writes the seccomp policy a systemd unit states, for unit-sandbox-exec:
# its SystemCallFilter= lines merged as systemd merges them (the first line
# decides allow- or deny-listing; an allow list implicitly holds @default;
# "~" lines remove from an allow list, plain lines from a deny list; an empty
# assignment resets), every @set resolved, recursively, by this machine's
# `systemd-analyze syscall-filter`; SystemCallErrorNumber= (default: kill)
# and RestrictAddressFamilies=. Usage: resolve_unit_sandbox.sh UNIT > POLICY
set -euo pipefail
unit=$1

values() { sed -n "s/^[[:space:]]*$1=//p" "$unit"; }

declare -A expanded=()
# Prints the system calls of the names given, sets (@...) resolved.
expand() {
  local name
  for name in "$@"; do
    if [[ $name == @* ]]; then
      [[ -n ${expanded[$name]:-} ]] && continue
      expanded[$name]=1
      local members
      members=$(systemd-analyze --no-pager syscall-filter "$name" | sed -n '2,$p' | grep -v '^[[:space:]]*#' | tr -s ' \t' '\n\n')
      [[ -n $members ]] || { echo "resolve_unit_sandbox: $unit: unknown set $name" >&2; exit 1; }
      # shellcheck disable=SC2086 # one name per word
      expand $members
    elif [[ $name == *:* ]]; then
      echo "resolve_unit_sandbox: $unit: per-call errno ($name) is not supported" >&2
      exit 1
    elif [[ -n $name ]]; then
      echo "$name"
    fi
  done
}

mode=""
declare -A listed=()
while IFS= read -r value; do
  if [[ -z $value ]]; then
    mode=""
    listed=()
    continue
  fi
  inverted=false
  [[ $value == ~* ]] && { inverted=true; value=${value#\~}; }
  if [[ -z $mode ]]; then
    if $inverted; then mode=deny; else mode=allow; fi
    if [[ $mode == allow ]]; then
      expanded=()
      while read -r call; do listed[$call]=1; done < <(expand @default)
    fi
  fi
  expanded=()
  # shellcheck disable=SC2086 # the value is a space-separated list
  calls=$(expand $value)
  for call in $calls; do
    if [[ $mode == allow && $inverted == false ]] || [[ $mode == deny && $inverted == true ]]; then
      listed[$call]=1
    else
      unset "listed[$call]"
    fi
  done
done < <(values SystemCallFilter)

errno=$(values SystemCallErrorNumber | tail -n 1)
families=$(values RestrictAddressFamilies | tr '\n' ' ')

echo "# The sandbox of $(basename "$unit"), resolved by resolve_unit_sandbox.sh"
echo "# with $(systemd-analyze --version | head -n 1)."
if [[ -n $mode ]]; then
  echo "mode $mode"
  echo "errno ${errno:-kill}"
  printf '%s\n' "${!listed[@]}" | sort | sed 's/^/syscall /'
fi
[[ -z ${families// /} ]] || echo "address_families ${families% }"
