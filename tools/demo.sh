#!/usr/bin/env bash
# make demo: until the daemon + virtual robot demo (tools/demo-daemon.sh,
# make demo-daemon) calibrates successfully, runs the offline
# pipeline end to end: simulate a large robot, calibrate, compare with truth.
set -euo pipefail
build=${1:-build}
out=$(mktemp -d)
"$build/tools/cdpr-sim/cdpr-sim" --preset large --poses 35 --seed 7 --anchor-perturbation 10 \
  --workspace 50,45,5,190,175,35 --out "$out"
"$build/tools/cdpr-calib/cdpr-calib" solve "$out/robot.toml" "$out/samples.csv" -o "$out/calibration.toml" \
  --truth "$out/truth.toml"
