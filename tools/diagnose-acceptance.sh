#!/bin/bash
# Issue 6's acceptance table for `cdpr-calib diagnose`: simulated data sets of
# the large robot (nominal anchors 2 m off, default noise) with
# effects hidden by cdpr-sim, one diagnose run each.
#
#   tools/diagnose-acceptance.sh [BUILD_DIR] [SEEDS] [NULL_SEEDS] [POSES]
#
# BUILD_DIR holds tools/cdpr-sim/cdpr-sim and tools/cdpr-calib/cdpr-calib
# (default build); SEEDS data sets per effect case (default 5), NULL_SEEDS
# without any effect (default 40), POSES per data set (default 45; one in
# three is held out). Per case it prints how often the expected
# effects were named exactly, the fitted values were within 3 sigma of the
# truth (final fit on all samples), the held-out normalized rms ended within
# 20 % of the noise floor (<= 1.2), the anchors improved against the plain
# catenary fit of the same samples, and "structure remains" was said.
# ONLY=REGEX limits the cases to those whose name matches.
set -euo pipefail
build=${1:-build}
seeds=${2:-5}
null_seeds=${3:-40}
poses=${4:-45}
sim=$build/tools/cdpr-sim/cdpr-sim
calib=$build/tools/cdpr-calib/cdpr-calib
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" <<<"$2"; }

# case NAME EXPECTED FIRST_SEED COUNT SIM_OPTIONS...
run_case() {
  local name=$1 expected=$2 first=$3 count=$4
  shift 4
  [[ $name =~ ${ONLY:-.} ]] || return 0
  local named=0 within=0 floor=0 better=0 structure=0 fitted=0 runs=0
  local start_sum=0 final_sum=0 base_sum=0 anchor_sum=0
  for ((seed = first; seed < first + count; ++seed)); do
    local dir=$work/$name-$seed
    "$sim" --preset large --poses "$poses" --seed "$seed" --anchor-perturbation 2 "$@" --out "$dir" >/dev/null
    local base
    base=$("$calib" solve -q "$dir/robot.toml" "$dir/samples.csv" -o "$dir/base.toml" --truth "$dir/truth.toml" |
           awk '$1 == "mean" { print $2 }')
    local line
    line=$("$calib" diagnose "$dir/robot.toml" "$dir/samples.csv" -o "$dir/report" --truth "$dir/truth.toml" \
           2>/dev/null | grep '^summary:')
    runs=$((runs + 1))
    [[ $line == "summary: failed" ]] && continue
    local added nrms0 nrms1 anchor sd
    added=$(field added "$line"); nrms0=$(field normalized_rms_start "$line"); nrms1=$(field normalized_rms_final "$line")
    anchor=$(field anchor_error_final "$line"); sd=$(field effect_sigma_distance "$line")
    # The same effects, in any order.
    if [[ $(tr ',' '\n' <<<"$added" | sort | paste -sd,) == $(tr ',' '\n' <<<"$expected" | sort | paste -sd,) ]]; then
      named=$((named + 1))
    fi
    [[ $line == *"structure=remains"* ]] && structure=$((structure + 1))
    awk -v a="$sd" -v e="$added" 'BEGIN { exit !(e != "none" && a <= 3.0) }' && within=$((within + 1))
    [[ $added != none ]] && fitted=$((fitted + 1))
    awk -v a="$nrms1" 'BEGIN { exit !(a <= 1.2) }' && floor=$((floor + 1))
    [[ -n $base ]] && awk -v a="$anchor" -v b="$base" 'BEGIN { exit !(a < b) }' && better=$((better + 1))
    start_sum=$(awk -v s="$start_sum" -v a="$nrms0" 'BEGIN { print s + a }')
    final_sum=$(awk -v s="$final_sum" -v a="$nrms1" 'BEGIN { print s + a }')
    base_sum=$(awk -v s="$base_sum" -v a="${base:-0}" 'BEGIN { print s + a }')
    anchor_sum=$(awk -v s="$anchor_sum" -v a="$anchor" 'BEGIN { print s + a }')
    echo "  $name seed $seed: added $added, nrms $nrms0 -> $nrms1, anchor error $base -> $anchor m," \
         "effect $sd sigma, ${line##*structure=}" | cut -c1-160 >&2
  done
  printf "| %-28s | %-26s | %5s | %9s | %8s | %9s | %9s | %15s | %9s |\n" "$name" "$expected" \
    "$named/$runs" "$within/$fitted" "$floor/$runs" \
    "$(awk -v s="$start_sum" -v f="$final_sum" -v n="$runs" 'BEGIN { printf "%.2f->%.2f", s / n, f / n }')" \
    "$better/$runs" "$(awk -v s="$base_sum" -v f="$anchor_sum" -v n="$runs" 'BEGIN { printf "%.3f->%.3f", s / n, f / n }')" \
    "$structure/$runs"
}

echo "| case (hidden in the data)    | expected named             | named | in 3 sigma | rms<=1.2 | mean nrms | anchor better | mean anchor err [m] | structure |"
echo "|---|---|---|---|---|---|---|---|---|"
run_case "EA 1.5e6 N" elasticity 11 "$seeds" --axial-stiffness 1.5e6
run_case "encoder scale 0.3 %" encoder_scale 11 "$seeds" --encoder-scale 0.003
run_case "load-cell bias 15 N" load_cell 11 "$seeds" --force-bias 15
run_case "CoM offset 5 cm" com_offset 11 "$seeds" --com-offset 0.03,0.04,0
run_case "pulley radius 0.15 m" pulley_radius 11 "$seeds" --pulley-radius 0.15
run_case "density error 5 %" density_error 11 "$seeds" --density-error 0.05
run_case "none (false positives)" none 101 "$null_seeds"
run_case "EA 1.5e6 N + bias 15 N" elasticity,load_cell 11 "$seeds" --axial-stiffness 1.5e6 --force-bias 15
run_case "enc. scale 0.3 % + bias 15 N" encoder_scale,load_cell 11 "$seeds" --encoder-scale 0.003 --force-bias 15
run_case "EA 1.5e6 N + CoM 5 cm" elasticity,com_offset 11 "$seeds" --axial-stiffness 1.5e6 --com-offset 0.03,0.04,0
run_case "wind 36 N (unknown)" none 11 "$seeds" --wind 30,20,0
run_case "wind 72 N (unknown)" none 11 "$seeds" --wind 60,40,0
run_case "wind 117 N (unknown)" none 11 "$seeds" --wind 100,60,0
