#!/usr/bin/env bash
# ctest tools.check_report.<fixture>: tools/check-report/check-report.sh on
# one small page of fixtures/, each made to show one failure the checker
# must catch. The page's leading comment says what to expect:
#   expect: pass         the check passes
#   expect: REGEX        a line of the checker's output matches (grep -E);
#                        the check then has to fail
#   expect-not: REGEX    no line matches
#   fixture_test.sh FIXTURE.html OUT_DIR
# Only the page "passes" is also screenshot and printed (the files must
# appear); the others are checked without (CHECK_REPORT_NO_SHOTS), which is
# where the checker's time goes.
set -euo pipefail
fixture=$1
out=$2
checker=$(cd "$(dirname "$0")/../../.." && pwd)/tools/check-report/check-report.sh
fail() { echo "FAIL: $*" >&2; exit 1; }

comment=$(sed -n '1,/-->/p' "$fixture")
mapfile -t expected < <(sed -n 's/.*expect: \(.*\)/\1/p' <<<"$comment" | sed 's/ *-->$//')
mapfile -t unexpected < <(sed -n 's/.*expect-not: \(.*\)/\1/p' <<<"$comment" | sed 's/ *-->$//')
[[ ${#expected[@]} -gt 0 ]] || fail "$fixture says nothing to expect"

rm -rf "$out"
no_shots=1
[[ ${expected[0]} != pass ]] || no_shots=
status=0
output=$(CHECK_REPORT_NO_SHOTS=$no_shots "$checker" "$fixture" "$out" 2>&1) || status=$?
echo "$output"
[[ $status -ne 77 ]] || exit 77

if [[ ${expected[0]} == pass ]]; then
  [[ $status -eq 0 ]] || fail "expected to pass, exit status $status"
  for file in screen-1280.png screen-794.png print-a4.pdf; do
    [[ -s $out/$file ]] || fail "no $out/$file"
  done
else
  [[ $status -eq 1 ]] || fail "expected to fail (exit status 1), exit status $status"
  for pattern in "${expected[@]}"; do
    grep -Eq -- "$pattern" <<<"$output" || fail "no line matches: $pattern"
  done
fi
for pattern in "${unexpected[@]}"; do
  if grep -Eq -- "$pattern" <<<"$output"; then fail "a line matches: $pattern"; fi
done
echo "as expected"
