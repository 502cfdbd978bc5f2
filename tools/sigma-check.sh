#!/usr/bin/env bash
# Are the daemon's sigmas honest? Runs tools/demo.sh (the daemon against the
# virtual robot, large preset, nominal anchors 0.3 m off, time scale 20) for
# virtual-robot seeds 1..N and compares each committed calibration with the
# robot's truth: the RMS over all runs of error/sigma of every anchor axis
# and every encoder offset (1 when the sigmas are honest), and the mean and
# worst anchor error. Runs SIGMA_CHECK_JOBS demos at a time (default 1: the
# virtual robot at 20x needs a core, or its CANopen heartbeats come late).
# Usage: tools/sigma-check.sh BUILD_DIR [N=20] [DEMO_SCRIPT=tools/demo.sh]
# Prints one line per run, then the summary. The runs' files stay in the
# directory named at the end.
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
runs=${2:-20}
demo=${3:-$(dirname "$0")/demo.sh}
jobs=${SIGMA_CHECK_JOBS:-1}
out=${SIGMA_CHECK_DIR:-$(mktemp -d /tmp/cdpr-sigma-check.XXXXXX)}

run_one() {
  DEMO_SEED=$1 DEMO_KEEP="$out/seed$1" nice -n 10 bash "$demo" "$build" >"$out/seed$1.log" 2>&1 ||
    echo "seed $1: demo failed (see $out/seed$1.log)" >&2
}
# SIGMA_CHECK_DIR=<a kept directory> only scores the runs already there.
[[ -n ${SIGMA_CHECK_DIR:-} ]] && jobs=0 && runs_to_start=0 || runs_to_start=$runs
for (( seed = 1; seed <= runs_to_start; seed += jobs )); do
  for (( k = seed; k < seed + jobs && k <= runs; k++ )); do run_one "$k" & done
  wait
done

for (( seed = 1; seed <= runs; seed++ )); do
  dir=$out/seed$seed
  [[ -f $dir/calibration.toml ]] || continue
  # calibration.toml, then truth.toml: one winch per [[winch]] table in order.
  awk -v seed="$seed" '
    FNR == 1 { file++; w = 0 }
    /^\[\[winch\]\]/ { w++ }
    { gsub(/[\[\],]/, " ") }
    $1 == "anchor" { for (a = 1; a <= 3; a++) anchor[file, w, a] = $(a + 2) }
    $1 == "anchor_sigma" { for (a = 1; a <= 3; a++) anchor_sigma[w, a] = $(a + 2) }
    $1 == "offset" { offset[file, w] = $3 }
    $1 == "offset_sigma" { offset_sigma[w] = $3 }
    END {
      for (i = 1; i <= w; i++) {
        e2 = 0
        for (a = 1; a <= 3; a++) {
          d = anchor[1, i, a] - anchor[2, i, a]; e2 += d * d
          printf "anchor_z %.6g\n", d / anchor_sigma[i, a]
        }
        printf "anchor_error %.6g\n", sqrt(e2)
        printf "offset_z %.6g\n", (offset[1, i] - offset[2, i]) / offset_sigma[i]
        printf "anchor_sigma_max %.6g\n", (anchor_sigma[i,1] > anchor_sigma[i,2] ? (anchor_sigma[i,1] > anchor_sigma[i,3] ? anchor_sigma[i,1] : anchor_sigma[i,3]) : (anchor_sigma[i,2] > anchor_sigma[i,3] ? anchor_sigma[i,2] : anchor_sigma[i,3]))
      }
    }' "$dir/calibration.toml" "$dir/truth.toml" >"$dir/z.txt"
  awk -v seed="$seed" '
    $1 == "anchor_z" || $1 == "offset_z" { s += $2 * $2; n++ }
    $1 == "anchor_error" { if ($2 > worst) worst = $2; sum += $2; m++ }
    $1 == "anchor_sigma_max" { if ($2 > sig) sig = $2 }
    END { printf "seed %2d: error/sigma rms %.3f, anchor error mean %.4f worst %.4f m, largest anchor sigma %.4f m\n",
          seed, sqrt(s / n), sum / m, worst, sig }' "$dir/z.txt"
done
cat "$out"/seed*/z.txt 2>/dev/null | awk -v runs="$runs" '
  $1 == "anchor_z" { sa += $2 * $2; na++ }
  $1 == "offset_z" { so += $2 * $2; no++ }
  $1 == "anchor_error" { if ($2 > worst) worst = $2; sum += $2; m++ }
  END {
    if (!m) { print "no run committed"; exit 1 }
    printf "%d of %d runs committed\n", m / 4, runs
    printf "error/sigma RMS: anchors+offsets %.3f, anchor axes %.3f, offsets %.3f\n",
           sqrt((sa + so) / (na + no)), sqrt(sa / na), sqrt(so / no)
    printf "anchor error: mean %.4f m, worst %.4f m\n", sum / m, worst
  }'
echo "runs kept in $out"
