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
