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
# the state, reports and logs there.
# Prints diagnose's summary line before and after, and the robot time of
# both runs. Exits non-zero when a step fails, not on the verdict.
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
seed=${2:-11}
case_robot=${CASE_ROBOT:---force-gain 0.03}
workspace=20,20,5,220,200,35  # the daemon's default [waypoints] box over the large robot's anchors
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

calibctl=("$build/tools/calibctl/calibctl" --socket "$work/control")
calib=$build/tools/cdpr-calib/cdpr-calib
history=$work/state/history
# The run's own lines of its run.toml (before its [[waypoint]] tables), comments dropped.
run_line() {
  awk '/^\[\[/ { exit } /^(outcome|robot_time_s|samples|strategy|extends) =/ { sub(/ *#.*/, ""); printf "%s; ", $0 }' \
    "$history/$1/run.toml"
  echo
}

echo "== run 1: the planned calibration (virtual robot seed $seed, $case_robot)"
"${calibctl[@]}" start >/dev/null
"${calibctl[@]}" status --follow --interval 2000 >"$work/run1.log" || true
run_line run-000001
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
