#!/usr/bin/env bash
# Where a calibration's robot time goes: one daemon run against the virtual
# robot (large preset, nominal anchors 0.3 m off, the 35-waypoint plan of
# the shipped [waypoints]) at a chosen time scale, then the move and settle
# time per waypoint from `calibctl status --follow` (sampled every 0.5 s of
# real time, so +-0.5 s x the time scale of robot time per phase).
#   tools/robot-time.sh BUILD_DIR OUT_DIR
# TIME_SCALE (default 1: real time, a run takes about 35 min), SEED (7),
# and daemon keys per section, as TOML lines: EQUILIBRIUM_KEYS,
# WAYPOINTS_KEYS, LIMITS_KEYS. E.g. the tour's share of the robot time:
#   WAYPOINTS_KEYS='order = "selection"' tools/robot-time.sh build out-selection
# and the sway estimate's:
#   EQUILIBRIUM_KEYS='estimate_sway = false' LIMITS_KEYS='settle_timeout_s = 900' \
#     tools/robot-time.sh build out-wait
# Only fault timeouts are loosened (CANopen heartbeats both ways, pose, load cell: the
# virtual robot's nodes share a thread with its physics, and a loaded machine
# delays them); no equilibrium threshold is. OUT_DIR keeps the status log,
# the daemon's log, its state (calibration.toml, history) and the robot's
# truth.toml; the summary is printed and written to OUT_DIR/summary.txt.
set -euo pipefail
build=$(cd "${1:?usage: tools/robot-time.sh BUILD_DIR OUT_DIR}" && pwd)
out=${2:?usage: tools/robot-time.sh BUILD_DIR OUT_DIR}
mkdir -p "$out"
out=$(cd "$out" && pwd)
scale=${TIME_SCALE:-1}
work=$(mktemp -d /tmp/cdpr-robot-time.XXXXXX)
# shellcheck source=tools/processes.bash
source "$(dirname "$0")/processes.bash"

cleanup() {
  local status=$?
  stop_started
  cp -r "$work"/*.log "$work/state" "$work/cdpr-calibd.toml" "$out/" 2>/dev/null || true
  cp "$work/robot/truth.toml" "$work/robot/robot.toml" "$out/" 2>/dev/null || true
  rm -rf "$work"
  exit $status
}
trap cleanup EXIT
trap 'exit 130' INT TERM

start_virtual_robot "$work" "$build" "$scale" "${SEED:-7}"

# 5 m/s of robot time, in the daemon's clock.
write_daemon_config "$work" \
  top='unsafe_ok = ["winches.heartbeat_timeout_ms", "winches.drive.consumer_heartbeat_ms",
  "load_cell.fault_timeout_ms", "limits.pose_stale_ms"]' \
  winches="max_speed_mps = $(awk -v s="$scale" 'BEGIN { print 5.0 * s }')
heartbeat_timeout_ms = 5000" \
  drive="consumer_heartbeat_ms = 5000" \
  load_cell="fault_timeout_ms = 10000" \
  equilibrium="${EQUILIBRIUM_KEYS:-}" \
  waypoints="${WAYPOINTS_KEYS:-}" \
  limits="pose_stale_ms = 5000
${LIMITS_KEYS:-}"

"$build/src/cdpr-calibd" --config "$work/cdpr-calibd.toml" --sim-clock "$work/robot/clock" 2>"$work/daemon.log" &
pids+=($!)
wait_for "$work/control" 30
sleep 1  # let the CANopen nodes' first heartbeats arrive

calibctl=("$build/tools/calibctl/calibctl" --socket "$work/control")
"${calibctl[@]}" start
"${calibctl[@]}" status --follow --interval 500 |
  while IFS= read -r line; do printf '%s %s\n' "$(date +%s.%N | cut -c1-14)" "$line"; done >"$work/status.log" || true
"${calibctl[@]}" show >"$work/show.log" 2>&1 || true

# A phase lasts from its first status line to the first line of the next.
awk -v scale="$scale" '
  $2 == "move" || $2 == "settle" {
    key = $2 " " $3
    if (key != last) { close_phase($1); last = key; since = $1; if (first == "") first = $1 }
    end = $1
  }
  function close_phase(t,   a, d) {
    if (last == "") return
    split(last, a, " "); d = (t - since) * scale; time[a[1]] += d; count[a[1]]++
    if (a[1] == "settle") { if (count["settle"] == 1 || d < lo) lo = d; if (d > hi) hi = d }
  }
  END {
    close_phase(end)
    printf "time scale %g; robot time from the first move to the last settle: %.1f min\n", scale, (end - first) * scale / 60
    printf "moves: %d, %.1f min (%.1f s each)\n", count["move"], time["move"] / 60, count["move"] ? time["move"] / count["move"] : 0
    printf "settles: %d, %.1f min (%.1f s each, %.1f-%.1f s)\n", count["settle"], time["settle"] / 60,
      count["settle"] ? time["settle"] / count["settle"] : 0, lo, hi
  }' <(sed 's/\[ *[0-9]*%\] //' "$work/status.log") | tee "$work/summary.log"
grep -E "robot_time|waypoints|stop" "$work/state/calibration.toml" 2>/dev/null | tee -a "$work/summary.log" || true
[[ -f $work/state/calibration.toml ]] || { echo "robot-time: no calibration was committed" >&2; exit 1; }
