#!/usr/bin/env bash
# make demo-offline: the offline pipeline end to end, no daemon: simulate a
# large robot (35 poses, nominal anchors 10 m off), calibrate with
# cdpr-calib, compare with the simulator's truth.
# Usage: tools/demo-offline.sh BUILD_DIR.
set -euo pipefail
build=${1:-build}
out=$(mktemp -d)
"$build/tools/cdpr-sim/cdpr-sim" --preset large --poses 35 --seed 7 --anchor-perturbation 10 \
  --workspace 50,45,5,190,175,35 --out "$out"
"$build/tools/cdpr-calib/cdpr-calib" solve "$out/robot.toml" "$out/samples.csv" -o "$out/calibration.toml" \
  --truth "$out/truth.toml"
