# Sourced by the scripts that run the daemon against the virtual robot
# (demo.sh, robot-time.sh): the processes they start, stopped in the right
# order, and waiting for the endpoints those processes create.

pids=()

# Stops every process in `pids`, newest first: the daemon stops (winches
# halted) before the robot it drives goes.
stop_started() {
  for (( k = ${#pids[@]} - 1; k >= 0; k-- )); do
    kill -TERM "${pids[k]}" 2>/dev/null || true
    wait "${pids[k]}" 2>/dev/null || true
  done
}

# Waits up to $2 seconds for file or socket $1.
wait_for() {
  for _ in $(seq 1 $(( $2 * 10 ))); do
    [[ -e $1 ]] && return 0
    sleep 0.1
  done
  echo "$(basename "$0"): $1 did not appear within $2 s" >&2
  return 1
}

# Starts the virtual robot (large preset, nominal anchors 0.3 m off, an FT-11
# load cell on Modbus RTU) with its endpoints in $1/robot, log in
# $1/virtual-robot.log, and waits until it serves them.
#   start_virtual_robot WORK BUILD TIME_SCALE SEED [more virtual-robot options]
start_virtual_robot() {
  local work=$1 build=$2 scale=$3 seed=$4
  shift 4
  "$build/tools/virtual-robot/virtual-robot" --preset large --seed "$seed" --time-scale "$scale" \
    --anchor-perturbation 0.3 --modbus-transport rtu --load-cell-model flintec-ft-11 "$@" \
    --endpoints "$work/robot" >"$work/virtual-robot.log" 2>&1 &
  pids+=($!)
  wait_for "$work/robot/ready" 60
}

# Writes $1/cdpr-calibd.toml: the daemon against the robot start_virtual_robot
# started in $1, state in $1/state, control socket $1/control. Each further
# argument SECTION=LINES adds TOML lines to that section ("top" is the top
# level, before the first table; "drive", "encoder", "mechanics" are
# [winches.drive], [winches.encoder], [winches.mechanics]); the keys are
# those of systemd/cdpr-calibd.toml.
#   write_daemon_config WORK [winches=...] [load_cell=...] [limits=...] ...
write_daemon_config() {
  local work=$1
  shift
  local -A keys=()
  local arg
  for arg in "$@"; do keys[${arg%%=*}]=${arg#*=}; done
  cat >"$work/cdpr-calibd.toml" <<CONFIG
# cdpr-calibd against the virtual robot (keys: systemd/cdpr-calibd.toml)
robot = "$work/robot/robot.toml"
${keys[top]:-}
[store]
state_dir = "$work/state"
[control]
socket = "$work/control"
[winches]
endpoint = "unix:$work/robot/can.sock"
${keys[winches]:-}
[winches.drive]
${keys[drive]:-}
[winches.encoder]
${keys[encoder]:-}
[winches.mechanics]
${keys[mechanics]:-}
[load_cell]
# The virtual FT-11 shows kilograms with two decimals.
endpoint = "rtu:$work/robot/load_cell.tty"
preset = "flintec-ft-11"
decimals = 2
${keys[load_cell]:-}
[pose]
endpoint = "unix:$work/robot/pose.sock"
[button]
kind = "none"
[equilibrium]
${keys[equilibrium]:-}
[waypoints]
${keys[waypoints]:-}
[limits]
${keys[limits]:-}
CONFIG
}
