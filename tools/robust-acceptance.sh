#!/bin/sh
# Measures the robust calibration's acceptance figures on simulated data
# (docs/measurements/robust-acceptance.md has the measured tables):
#   1. gross errors: pulley error at 0/5/10/20 % rows with a 0.5-2 m encoder
#      error (+ 5 % load-cell spikes of 50-500 N at 5-20 %), large/35 and
#      large/9 (10 m off), small/8 (1 m off); recall, clean rows rejected,
#      error/sigma RMS;
#   2. every start at the truth-started minimum: 10 m / 1 m and 20 m / 2 m
#      off, 9, 35 and 45 poses;
#   3. mis-modelled data flagged by the model-fit test, effect-free never.
# Usage: tools/robust-acceptance.sh BUILD_DIR [SEEDS] [START_SEEDS] [MISFIT_SEEDS]
set -eu
build=${1:?usage: $0 BUILD_DIR [SEEDS] [START_SEEDS] [MISFIT_SEEDS]}
seeds=${2:-50}
start_seeds=${3:-200}
misfit_seeds=${4:-20}
acc="$build/tools/cdpr-accuracy/cdpr-accuracy"

echo "## gross errors ($seeds seeds each)"
for spec in "large 35 10" "large 9 10" "small 8 1"; do
  set -- $spec
  for fraction in 0 0.05 0.1 0.2; do
    spikes=0.05
    [ "$fraction" = 0 ] && spikes=0
    echo "### $1/$2, $3 m off, encoder outliers $fraction, force spikes $spikes"
    "$acc" --preset "$1" --poses "$2" --anchor-perturbation "$3" --seeds "$seeds" \
      --encoder-outliers "$fraction" --force-spikes "$spikes" 2>/dev/null
  done
done

echo "## starts ($start_seeds seeds at 10 m / 1 m, a quarter of them at 20 m / 2 m)"
for spec in "large 10 $start_seeds" "large 20 $((start_seeds / 4))" "small 1 $start_seeds" "small 2 $((start_seeds / 4))"; do
  set -- $spec
  for poses in 9 35 45; do
    echo "### $1/$poses, $2 m off"
    "$acc" --preset "$1" --poses "$poses" --anchor-perturbation "$2" --seeds "$3" --truth-start 2>/dev/null
  done
done

echo "## model-fit test ($misfit_seeds seeds, large, 90 poses)"
for effect in "" "--density-error -0.999" "--com-offset 0,0,1" "--density-error 0.05"; do
  echo "### data: ${effect:-effect-free}"
  "$acc" --preset large --poses 90 --seeds "$misfit_seeds" $effect 2>/dev/null
done
