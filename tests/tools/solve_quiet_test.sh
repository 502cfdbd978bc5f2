#!/usr/bin/env bash
# ctest tools.cdpr_calib.solve_quiet: `cdpr-calib solve -q` on data its model
# cannot fit (rigid weightless cables solved as catenaries) says so in one
# short first line on stderr, exits 3, and keeps the term list for the
# summary; without -q stderr carries the whole warning.
set -euo pipefail
bin=$1
dir=$(mktemp -d /tmp/cdpr-solve-quiet.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$bin/tools/cdpr-sim/cdpr-sim" --out "$dir/data" --preset large --anchor-perturbation 2 --poses 45 --seed 1 \
  --weightless-cables --segments 400 >/dev/null
calib="$bin/tools/cdpr-calib/cdpr-calib"
status=0
"$calib" solve -q "$dir/data" -o "$dir/quiet.toml" >/dev/null 2>"$dir/quiet.err" || status=$?
[[ $status == 3 ]] || fail "exit $status, expected 3 (written, flagged): $(cat "$dir/quiet.err")"
first=$(head -n 1 "$dir/quiet.err")
[[ $first == "cdpr-calib: the model does not fit the data: chi-square "* ]] || fail "first line: $first"
((${#first} <= 200)) || fail "first line of ${#first} characters with -q: $first"
grep -q 'diagnose' "$dir/quiet.err" || fail "no pointer to diagnose: $(cat "$dir/quiet.err")"
if grep -q 'density_error' "$dir/quiet.err"; then fail "the term list on stderr with -q: $(cat "$dir/quiet.err")"; fi

status=0
"$calib" solve "$dir/data" -o "$dir/loud.toml" >/dev/null 2>"$dir/loud.err" || status=$?
[[ $status == 3 ]] || fail "exit $status without -q"
grep -q 'the model lacks a term the data ask for' "$dir/loud.err" || fail "no term list without -q: $(cat "$dir/loud.err")"
echo "ok"
