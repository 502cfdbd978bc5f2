#!/usr/bin/env bash
# The discriminating waypoints measured by the daemon (issue 35 item 4, on
# the robot's side of tools/discriminate-acceptance.sh): the virtual robot
# (large preset, nominal anchors 0.3 m off) hides a load-cell gain; the
# daemon calibrates it as the button would; `cdpr-calib diagnose` on the
# run's history entry names a mimic set and writes waypoints.csv;
# `calibctl start --waypoints ... --append-to 1` measures them after that
# run's rows; diagnose on the new entry should name the gain alone.
#
#   tools/discriminate-daemon.sh [BUILD_DIR] [SEED]
#
# CASE_ROBOT replaces the hidden effect (virtual-robot options, default
# "--force-gain 0.03"); WAYPOINTS_KEYS adds [waypoints] lines for run 1
# (e.g. "count = 12": fewer poses, more often a mimic set); KEEP=DIR keeps
# the state, reports and logs there. EARLIER=sim makes run 1 the rows
# cdpr-sim measures on the same true robot (45 poses, single readings with
# robot.toml's sigmas, as tools/discriminate-acceptance.sh has them: a
# mimic set far more often than the daemon's window-averaged rows), put in
# the history as a kept run before the daemon starts; run 2 is the daemon's.
# Prints diagnose's summary line before and after, and the robot time of
# both runs. Exits non-zero when a step fails, not on the verdict.
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
seed=${2:-11}
case_robot=${CASE_ROBOT:---force-gain 0.03}
work=$(mktemp -d /tmp/cdpr-discriminate.XXXXXX)
# shellcheck source=tools/processes.bash
source "$(dirname "$0")/processes.bash"

cleanup() {
  local status=$?
  stop_started
  if [[ -n ${KEEP:-} ]]; then
    mkdir -p "$KEEP"
    cp -r "$work"/*.log "$work/state" "$work/d1" "$work/d2" "$work/robot/truth.toml" "$KEEP/" 2>/dev/null || true
  fi
  rm -rf "$work"
  exit $status
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# shellcheck disable=SC2086 # case_robot is a list of options
start_virtual_robot "$work" "$build" 20 "$seed" $case_robot
history=$work/state/history
if [[ ${EARLIER:-daemon} == sim ]]; then
  # shellcheck disable=SC2086
  "$build/tools/cdpr-sim/cdpr-sim" --preset large --seed "$seed" --anchor-perturbation 0.3 --poses 45 $case_robot \
    --out "$work/earlier" >/dev/null
  cmp -s "$work/earlier/truth.toml" "$work/robot/truth.toml" ||
    echo "note: cdpr-sim's truth.toml differs from the virtual robot's"
  mkdir -p "$history/run-000001"
  cp "$work/earlier/robot.toml" "$work/earlier/samples.csv" "$history/run-000001/"
  cat >"$history/run-000001/run.toml" <<RUN
format = 1
run = 1
outcome = "failed"
reason = "cdpr-sim --seed $seed --poses 45 $case_robot, put in as a kept run"
robot = "large"
started = "2026-12-07T00:00:00Z"
robot_time_s = 0
waypoints_planned = 45
samples = 45
skipped = 0
RUN
fi
write_daemon_config "$work" \
  top='unsafe_ok = ["winches.heartbeat_timeout_ms", "limits.pose_stale_ms"]' \
  winches="max_speed_mps = 100.0
heartbeat_timeout_ms = 2000" \
  waypoints="${WAYPOINTS_KEYS:-}" \
  limits="settle_timeout_s = 15.0
pose_stale_ms = 2000"
"$build/src/cdpr-calibd" --config "$work/cdpr-calibd.toml" --sim-clock "$work/robot/clock" 2>"$work/daemon.log" &
pids+=($!)
wait_for "$work/control" 30
sleep 1  # let the CANopen nodes' first heartbeats arrive

# The daemon's default [waypoints] box: robot.toml's (nominal) anchors' footprint inset by
# margin_m 20, z 5-35 m. A waypoint a few cm outside it is refused, as a planned one would be.
workspace=$(awk 'BEGIN { n = 0 } /^anchor = \[/ { gsub(/[\[\],]/, " "); x[n] = $3; y[n] = $4; n++ }
  END { lx = hx = x[0]; ly = hy = y[0]
        for (i = 1; i < n; i++) { if (x[i] < lx) lx = x[i]; if (x[i] > hx) hx = x[i]; if (y[i] < ly) ly = y[i]; if (y[i] > hy) hy = y[i] }
        printf "%.3f,%.3f,5,%.3f,%.3f,35", lx + 20.001, ly + 20.001, hx - 20.001, hy - 20.001 }' "$work/robot/robot.toml")
calibctl=("$build/tools/calibctl/calibctl" --socket "$work/control")
calib=$build/tools/cdpr-calib/cdpr-calib
# The run's own lines of its run.toml (before its [[waypoint]] tables), comments dropped.
run_line() {
  awk '/^\[\[/ { exit } /^(outcome|robot_time_s|samples|strategy|extends) =/ { sub(/ *#.*/, ""); printf "%s; ", $0 }' \
    "$history/$1/run.toml"
  echo
}

if [[ ${EARLIER:-daemon} == sim ]]; then
  echo "== run 1: cdpr-sim's 45 poses of the same robot (seed $seed, $case_robot)"
else
  echo "== run 1: the planned calibration (virtual robot seed $seed, $case_robot)"
  "${calibctl[@]}" start >/dev/null
  "${calibctl[@]}" status --follow --interval 2000 >"$work/run1.log" || true
  run_line run-000001
fi
"$calib" diagnose "$history/run-000001" -o "$work/d1" --discriminate 8 --workspace "$workspace" \
  >"$work/diagnose1.log" 2>&1 || true
echo "before: $(grep '^summary:' "$work/diagnose1.log" || echo "no summary (see diagnose1.log)")"
[[ -f $work/d1/waypoints.csv ]] || { echo "no mimic set, no waypoints: nothing to measure"; exit 0; }
echo "waypoints: $(grep -c '^[0-9-]' "$work/d1/waypoints.csv")"

echo "== run 2: those waypoints after run 1's rows"
"${calibctl[@]}" start --waypoints "$work/d1/waypoints.csv" --append-to 1
"${calibctl[@]}" status --follow --interval 2000 >"$work/run2.log" || true
run_line run-000002
"$calib" diagnose "$history/run-000002" -o "$work/d2" --discriminate 0 >"$work/diagnose2.log" 2>&1 || true
echo "after:  $(grep '^summary:' "$work/diagnose2.log" || echo "no summary (see diagnose2.log)")"
