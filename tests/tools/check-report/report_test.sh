#!/usr/bin/env bash
# ctest tools.report_browser.<kind>: writes one kind of report the way a
# user does and checks it in headless Chromium
# (tools/check-report/check-report.sh): no console error, nothing wider
# than the viewport (1280 px and A4's 794 px), no empty plot, no clipped
# label, self-contained, valid HTML5.
#   report_test.sh KIND BUILD_DIR OUT_DIR
# OUT_DIR keeps the data, the report and what the checker saw
# (OUT_DIR/check: screen-1280.png, screen-794.png, print-a4.pdf,
# verdict.txt). A kind is one case below plus its name in
# CDPR_REPORT_KINDS (tests/CMakeLists.txt).
set -euo pipefail
kind=$1
build=$2
out=$3
checker=$(cd "$(dirname "$0")/../../.." && pwd)/tools/check-report/check-report.sh
sim=$build/tools/cdpr-sim/cdpr-sim
calib=$build/tools/cdpr-calib/cdpr-calib

rm -rf "$out"
mkdir -p "$out"
# simulate SIM_OPTIONS...: a data set in $out/data (large robot, 45 poses).
simulate() {
  "$sim" --preset large --anchor-perturbation 2 --poses 45 "$@" --out "$out/data" >/dev/null
}

case $kind in
  diagnose-effect)  # an effect named and fitted: before and after plots
    simulate --seed 11 --axial-stiffness 1.5e6
    "$calib" diagnose "$out/data/robot.toml" "$out/data/samples.csv" -o "$out/report" >"$out/diagnose.txt" 2>&1
    report=$out/report/report.html ;;
  diagnose-structure)  # no effect explains the data: structure remains
    simulate --seed 11 --wind 100,60,0
    "$calib" diagnose "$out/data/robot.toml" "$out/data/samples.csv" -o "$out/report" >"$out/diagnose.txt" 2>&1
    report=$out/report/report.html ;;
  diagnose-drift)  # structure remains, named as a trend over sample order
    simulate --seed 21 --encoder-drift 0:0.06,3:-0.06
    "$calib" diagnose "$out/data/robot.toml" "$out/data/samples.csv" -o "$out/report" >"$out/diagnose.txt" 2>&1
    report=$out/report/report.html ;;
  solve)  # a plain calibration: the verdict card, anchors and residuals
    simulate --seed 12
    "$calib" solve -q "$out/data/robot.toml" "$out/data/samples.csv" -o "$out/calibration.toml" \
      --report "$out/report" >"$out/solve.txt" 2>&1
    report=$out/report/report.html ;;
  solve-misfit)  # the model does not fit: the card says so and points to diagnose
    simulate --seed 21 --encoder-drift 0:0.06,3:-0.06
    "$calib" solve -q "$out/data/robot.toml" "$out/data/samples.csv" -o "$out/calibration.toml" \
      --accept-misfit --report "$out/report" >"$out/solve.txt" 2>&1
    report=$out/report/report.html ;;
  *)
    echo "unknown report kind $kind" >&2
    exit 2 ;;
esac

[[ -s $report ]] || { echo "FAIL: no report $report" >&2; exit 1; }
"$checker" "$report" "$out/check"
