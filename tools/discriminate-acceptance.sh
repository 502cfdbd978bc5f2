#!/bin/bash
# The acceptance of the discriminating waypoints (issue 35 item 4): on data
# where diagnose names a mimic set, do the waypoints it proposes make the
# true term alone come out once they are measured?
#
#   tools/discriminate-acceptance.sh [BUILD_DIR] [SEEDS] [POSES] [COUNT]
#
# Per seed (11 onwards, like tools/diagnose-acceptance.sh): cdpr-sim
# simulates POSES poses (default 45) of the large robot (nominal anchors 2 m
# off) with a hidden 3 % load-cell gain; cdpr-calib diagnose proposes COUNT
# waypoints (default 8) in the daemon's default workspace (the anchors'
# footprint inset 20 m, z 5-35 m); cdpr-sim measures them with the same
# robot and noise (--extra-positions) and diagnose runs again on all rows.
# Counted: before, the gain named or in a mimic set; after, the gain named
# alone (no mimic set). CASE_SIM replaces the hidden effect's options,
# EXPECTED the term (e.g. CASE_SIM="--axial-stiffness 2e6" EXPECTED=elasticity).
set -euo pipefail
build=${1:-build}
seeds=${2:-10}
poses=${3:-45}
count=${4:-8}
case_sim=${CASE_SIM:---force-gain 0.03}
expected=${EXPECTED:-load_cell}
workspace=20,20,5,220,200,35
sim=$build/tools/cdpr-sim/cdpr-sim
calib=$build/tools/cdpr-calib/cdpr-calib
work=${WORK:-$(mktemp -d)}
[[ -n ${WORK:-} ]] || trap 'rm -rf "$work"' EXIT

field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" <<<"$2"; }
in_set() { [[ ";$2;" == *";$1;"* || "|$2|" == *"|$1|"* || $2 == *"|$1;"* || $2 == *";$1|"* || $2 == "$1|"* || $2 == *"|$1" ]]; }

before_named=0 before_set=0 proposed=0 after_alone=0 after_named=0 runs=0
printf '%-5s %-28s %-40s %-6s %-28s %s\n' seed "before: added" "mimic" wps "after: added" mimic
for ((seed = 11; seed < 11 + seeds; ++seed)); do
  dir=$work/seed-$seed
  # shellcheck disable=SC2086 # case_sim is a list of options
  "$sim" --preset large --anchor-perturbation 2 --poses "$poses" --seed "$seed" $case_sim --out "$dir/before" >/dev/null
  line=$("$calib" diagnose "$dir/before/robot.toml" "$dir/before/samples.csv" -o "$dir/before/report" \
         --discriminate "$count" --workspace "$workspace" 2>/dev/null | grep '^summary:' || true)
  runs=$((runs + 1))
  added=$(field added "$line"); mimic=$(field mimic "$line")
  [[ $added == "$expected" ]] && before_named=$((before_named + 1))
  { [[ $added == "$expected" ]] || in_set "$expected" "$mimic"; } && before_set=$((before_set + 1))
  after_added=- after_mimic=- wps=0
  if [[ -f $dir/before/report/waypoints.csv ]]; then
    wps=$(grep -c '^[0-9-]' "$dir/before/report/waypoints.csv" || true)
    proposed=$((proposed + 1))
    # shellcheck disable=SC2086
    "$sim" --preset large --anchor-perturbation 2 --poses "$poses" --seed "$seed" $case_sim \
      --extra-positions "$dir/before/report/waypoints.csv" --out "$dir/after" >/dev/null
    after=$("$calib" diagnose "$dir/after/robot.toml" "$dir/after/samples.csv" -o "$dir/after/report" \
            --discriminate 0 2>/dev/null | grep '^summary:' || true)
    after_added=$(field added "$after"); after_mimic=$(field mimic "$after")
  else
    after_added=$added after_mimic=$mimic
  fi
  [[ $after_added == "$expected" ]] && after_named=$((after_named + 1))
  [[ $after_added == "$expected" && $after_mimic == none ]] && after_alone=$((after_alone + 1))
  printf '%-5s %-28s %-40s %-6s %-28s %s\n' "$seed" "$added" "$mimic" "$wps" "$after_added" "$after_mimic"
done
echo
echo "case: $case_sim, $poses poses, $count waypoints in $workspace"
echo "before: named $before_named/$runs, named or in a mimic set $before_set/$runs; waypoints proposed in $proposed/$runs"
echo "after:  named $after_named/$runs, named alone (no mimic set) $after_alone/$runs"
