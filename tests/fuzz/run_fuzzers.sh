#!/usr/bin/env bash
# Runs the libFuzzer binaries of a CDPR_FUZZ=ON build one after the other
# (make fuzz), each for SECONDS, from its seed corpus in tests/fuzz/corpus/
# (read only: new inputs go to <build>/fuzz-corpus/<name>) with its
# dictionary when there is one, and prints libFuzzer's final stats: execs,
# coverage (cov: edges, ft: features), corpus size, crashes.
# Usage: run_fuzzers.sh <fuzz build dir> <seconds> [target...]
# Exit status: non-zero when any fuzzer found a crash (its input is kept in
# <build>/fuzz-artifacts/ and named in the summary).
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
build="$(cd "$1" && pwd)"
seconds="$2"
shift 2
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
  targets=(robot_toml samples_csv calibration_toml control_request can_frames modbus_reply modbus_frames pose_stream)
fi
mkdir -p "$build/fuzz-corpus" "$build/fuzz-artifacts" "$build/fuzz-logs"
summary=()
failed=0
for name in "${targets[@]}"; do
  binary="$build/tests/fuzz/fuzz_$name"
  if [[ ! -x "$binary" ]]; then
    echo "fuzz: $binary missing (build the 'fuzzers' target first)" >&2
    exit 2
  fi
  work="$build/fuzz-corpus/$name"
  log="$build/fuzz-logs/$name.log"
  mkdir -p "$work"
  options=(-max_total_time="$seconds" -print_final_stats=1 -timeout=10 -max_len=4096
           -artifact_prefix="$build/fuzz-artifacts/$name-")
  [[ -f "$here/dict/$name.dict" ]] && options+=(-dict="$here/dict/$name.dict")
  echo "fuzz: $name for ${seconds}s (log: $log)"
  "$binary" "${options[@]}" "$work" "$here/corpus/$name" >"$log" 2>&1
  status=$?
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+[[:space:]]' "$log" | tail -1)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  corp=$(sed -n 's/.* corp: \([0-9]*\).*/\1/p' <<<"$last")
  if [[ $status -eq 0 ]]; then
    result="clean"
  else
    result="CRASH (exit $status): $(grep -o "Test unit written to .*" "$log" | tail -1)"
    failed=1
  fi
  summary+=("$(printf '%-18s execs %-10s exec/s %-7s cov %-6s ft %-7s corpus %-6s %s' \
    "$name" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" "$result")")
  grep -E '^(stat::|#[0-9]+[[:space:]]+DONE)' "$log"
done
echo
echo "fuzz summary (${seconds}s each):"
printf '  %s\n' "${summary[@]}"
exit $failed
