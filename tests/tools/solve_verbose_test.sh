#!/usr/bin/env bash
# ctest tools.cdpr_calib.solve_verbose: `cdpr-calib solve -v` lists the
# stages the calibration ran (docs/calibration.md, "The stages of a
# calibration"), a fallback marked as such; without -v it does not.
set -euo pipefail
bin=$1
dir=$(mktemp -d /tmp/cdpr-solve-verbose.XXXXXX)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# 35 poses, nominal anchors 3 m off, one row in twenty with a gross encoder
# error: a robust fit, a refit without it, and other starts as a fallback.
"$bin/tools/cdpr-sim/cdpr-sim" --out "$dir/data" --seed 7 --anchor-perturbation 3 --encoder-outliers 0.05 \
  --segments 400 >/dev/null
calib="$bin/tools/cdpr-calib/cdpr-calib"
"$calib" solve "$dir/data" -o "$dir/calibration.toml" -q -v --accept-misfit >"$dir/verbose.txt"
"$calib" solve "$dir/data" -o "$dir/calibration.toml" -q --accept-misfit >"$dir/plain.txt"

grep -q '^stages (docs/calibration.md' "$dir/verbose.txt" || fail "no stage list with -v: $(cat "$dir/verbose.txt")"
for stage in 'robust fit, Huber' 'gross-error test' 'refit without the gross errors' \
  '  final fit, least squares' 'other starts \[fallback\]'; do
  grep -Eq "^  $stage" "$dir/verbose.txt" || fail "stage '$stage' missing: $(cat "$dir/verbose.txt")"
done
grep -Eq '^  robust fit, Huber +[1-9][0-9]* it  cost [0-9.e+]+ ' "$dir/verbose.txt" ||
  fail "the Huber stage lacks its iterations or cost: $(cat "$dir/verbose.txt")"
if grep -q '^stages' "$dir/plain.txt"; then fail "stages listed without -v"; fi
echo "ok"
