#!/usr/bin/env bash
# make demo: the whole field calibration against the virtual robot, over the
# real protocols, in the foreground without systemd:
#   1. the virtual robot (large preset, physics time-scaled) serves CANopen on
#      a Unix socket, a Flintec FT-11 style load cell on Modbus RTU (a
#      pseudo-terminal) and a pose stream;
#   2. cdpr-calibd starts with a temporary state directory and a
#      configuration pointing at those endpoints;
#   3. `calibctl start` presses the button, `calibctl status --follow` shows
#      the progress, `calibctl show` the committed calibration;
#   4. the result is compared with the virtual robot's truth.toml.
# Usage: tools/demo.sh BUILD_DIR. Everything it starts is stopped on exit
# (the daemon first, so it never sees its robot vanish). Exits non-zero when
# the calibration is not committed or an anchor is 0.10 m or more off.
# DEMO_SEED picks the virtual robot (default 7); DEMO_KEEP=DIR copies the
# committed calibration.toml and the robot's truth.toml there, and the
# daemon's history (each run's samples, log and model check) to DIR/history.
# DEMO_EFFECTS adds virtual-robot options, e.g. a hidden effect such as
# "--force-bias 15" or "--axial-stiffness 1.5e6" (virtual-robot --help).
# DEMO_QUIRKS (make demo QUIRKS=...) has the robot's CANopen nodes play a
# vendor quirk profile: two-tpdo-encoder, rtr-bit30, no-type-255 or
# rpm-units (docs/fieldbus.md, "Vendor quirks"); the daemon is given the
# EDS files the nodes play (the robot writes them beside robot.toml) and
# the virtual winch's mechanics (0.2 m drum, gear 10).
set -euo pipefail
build=$(cd "${1:-build}" && pwd)
work=$(mktemp -d /tmp/cdpr-demo.XXXXXX)
# shellcheck source=tools/processes.bash
source "$(dirname "$0")/processes.bash"

cleanup() {
  local status=$?
  stop_started
  if [[ $status -ne 0 ]]; then
    echo "demo failed; logs:" >&2
    tail -n 20 "$work"/*.log >&2 || true
  fi
  rm -rf "$work"
  exit $status
}
trap cleanup EXIT
trap 'exit 130' INT TERM

start=$(date +%s)
echo "== virtual robot: large preset (240 x 220 x 50 m, 34 kg platform), physics 20x real time,"
echo "   nominal anchors in robot.toml 0.3 m off the truth, encoder offsets unknown"
quirks=${DEMO_QUIRKS:-none}
[[ $quirks != none ]] && echo "   CANopen nodes playing the vendor quirk profile $quirks"
start_virtual_robot "$work" "$build" 20 "${DEMO_SEED:-7}" --canopen-quirks "$quirks" ${DEMO_EFFECTS:-}

# The physics runs 20x faster: a 2 m/s cable pays out 40 m per real second.
# The virtual robot's CANopen nodes and pose stream share one thread with its
# physics, whose equilibrium solve can hold them past the shipped 500 ms
# (a hard move, a busy machine); a real drive or tracker does not wait for
# physics: hence the heartbeat and pose_stale_ms, beyond what a robot should
# run with, so acknowledged in unsafe_ok. The daemon runs on the robot's
# clock (--sim-clock), so a robot starved of CPU by a busy machine is a
# slower robot to it, not a silent node.
write_daemon_config "$work" \
  top='unsafe_ok = ["winches.heartbeat_timeout_ms", "limits.pose_stale_ms"]' \
  winches="max_speed_mps = 100.0
heartbeat_timeout_ms = 2000" \
  limits="settle_timeout_s = 15.0
pose_stale_ms = 2000" \
  drive="eds = \"$work/robot/drive.eds\"" \
  encoder="eds = \"$work/robot/encoder.eds\"" \
  mechanics="drum_diameter_m = 0.2
gear_ratio = 10.0"

echo "== cdpr-calibd (foreground, state in $work/state)"
"$build/src/cdpr-calibd" --config "$work/cdpr-calibd.toml" --sim-clock "$work/robot/clock" 2>"$work/daemon.log" &
pids+=($!)
wait_for "$work/control" 30
sleep 1  # let the CANopen nodes' first heartbeats arrive

calibctl=("$build/tools/calibctl/calibctl" --socket "$work/control")
echo "== calibctl start (the button)"
"${calibctl[@]}" start
echo "== calibctl status --follow"
"${calibctl[@]}" status --follow --interval 1000
[[ -f $work/state/calibration.toml ]] || { echo "demo: no calibration was committed" >&2; exit 1; }
echo "== calibctl show"
"${calibctl[@]}" show

if [[ -n ${DEMO_KEEP:-} ]]; then
  mkdir -p "$DEMO_KEEP"
  cp "$work/state/calibration.toml" "$work/robot/truth.toml" "$work/robot/robot.toml" "$DEMO_KEEP/"
  [[ -d $work/state/history ]] && cp -r "$work/state/history" "$DEMO_KEEP/"
fi
echo "== against the virtual robot's truth"
awk '
  FNR == 1 { file++ }
  /^anchor = \[/ { gsub(/[\[\],]/, " "); n[file]++; x[file, n[file]] = $3; y[file, n[file]] = $4; z[file, n[file]] = $5 }
  /^offset = / { m[file]++; o[file, m[file]] = $3 }
  END {
    printf "%-6s %16s %16s %16s\n", "cable", "anchor error [m]", "nominal was [m]", "offset error [m]"
    for (i = 1; i <= n[1]; i++) {
      e = sqrt((x[1,i]-x[2,i])^2 + (y[1,i]-y[2,i])^2 + (z[1,i]-z[2,i])^2)
      p = sqrt((x[3,i]-x[2,i])^2 + (y[3,i]-y[2,i])^2 + (z[3,i]-z[2,i])^2)
      printf "%-6d %16.4f %16.4f %+16.4f\n", i - 1, e, p, o[1,i] - o[2,i]
      if (e > worst) worst = e
    }
    printf "worst anchor error %.4f m: %s\n", worst, worst < 0.10 ? "within 0.10 m" : "NOT within 0.10 m"
    exit worst < 0.10 ? 0 : 1
  }' "$work/state/calibration.toml" "$work/robot/truth.toml" "$work/robot/robot.toml"
echo "== demo finished in $(( $(date +%s) - start )) s"
