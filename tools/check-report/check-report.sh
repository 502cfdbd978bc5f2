#!/usr/bin/env bash
# Checks an HTML report the way a reader meets it, in headless Chromium:
#   tools/check-report/check-report.sh REPORT.html [OUT_DIR]
# A copy of the report, alone in a scratch folder (so anything it needs
# besides itself is missing, and every host name fails to resolve), is
# loaded with check.js injected at the start of <head>, at a screen width
# (1280 px) and an A4 width (794 px). It fails on any script or console
# error, a resource that did not load or was loaded at all, anything wider
# than the viewport, a plot without data marks and a plot label cut off by
# the plot's edge (check.js says what counts as a plot). HTML5 validity is
# checked with tidy: every warning of it fails except those about SVG
# presentation attributes on <svg>, which it does not know.
# OUT_DIR (default: REPORT's name without .html, plus .check) receives the
# first screen at both widths (screen-1280.png, screen-794.png), the report
# printed on A4 (print-a4.pdf), verdict.txt and chromium.log.
# Exit status: 0 passed, 1 failed, 2 usage, 77 Chromium or tidy missing
# (ctest's skip code: tools/install-deps.sh chromium tidy installs them).
# CHROMIUM names the browser binary; CHROMIUM_FLAGS adds options;
# CHECK_REPORT_NO_SHOTS=1 only checks (no screenshots, no print);
# CHECK_REPORT_TIMEOUT bounds each browser run [s] (default 60).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [[ $# -lt 1 || $# -gt 2 || ! -f $1 ]]; then
  echo "usage: $0 REPORT.html [OUT_DIR]" >&2
  exit 2
fi
report=$1
out=${2:-${report%.html}.check}

browser=${CHROMIUM:-}
if [[ -z $browser ]]; then
  for candidate in chromium chromium-browser google-chrome; do
    if command -v "$candidate" >/dev/null; then browser=$candidate; break; fi
  done
fi
missing=()
[[ -n $browser ]] && command -v "$browser" >/dev/null || missing+=("chromium")
command -v tidy >/dev/null || missing+=("tidy")
if [[ ${#missing[@]} -gt 0 ]]; then
  echo "SKIPPED: ${missing[*]} not installed (tools/install-deps.sh ${missing[*]}; make test installs them)" >&2
  exit 77
fi

mkdir -p "$out"
scratch=$(mktemp -d /tmp/cdpr-check-report.XXXXXX)
trap 'rm -rf "$scratch"' EXIT
: >"$out/chromium.log"

# inject FILE TEXT: FILE with TEXT right after <head ...> (else after <html
# ...>, else after <!DOCTYPE ...>, else first), so it runs before anything
# of the report.
inject() {
  local html anchor=''
  html=$(<"$1")
  local -a patterns=('<[hH][eE][aA][dD]([[:space:]][^>]*)?>' '<[hH][tT][mM][lL]([[:space:]][^>]*)?>' '<![dD][oO][cC][tT][yY][pP][eE][^>]*>')
  for pattern in "${patterns[@]}"; do
    if [[ $html =~ $pattern ]]; then anchor=${BASH_REMATCH[0]}; break; fi
  done
  if [[ -n $anchor ]]; then
    printf '%s\n' "${html/"$anchor"/"$anchor$2"}"
  else
    printf '%s%s\n' "$2" "$html"
  fi
}

# run_browser ARGS...: one headless Chromium run on its own profile, output
# on stdout, its chatter appended to chromium.log. As root Chromium refuses
# to start without --no-sandbox.
run_browser() {
  local -a flags=(--headless --disable-gpu --no-first-run --disable-extensions --hide-scrollbars
                  --user-data-dir="$scratch/profile" --host-resolver-rules="MAP * ~NOTFOUND")
  [[ $(id -u) -ne 0 ]] || flags+=(--no-sandbox)
  # shellcheck disable=SC2086 # CHROMIUM_FLAGS is a list of options
  timeout "${CHECK_REPORT_TIMEOUT:-60}" "$browser" "${flags[@]}" ${CHROMIUM_FLAGS:-} "$@" 2>>"$out/chromium.log"
}

# check.js as a file of its own: the report keeps its line numbers.
cp "$here/check.js" "$scratch/cdpr-report-check.js"
inject "$report" '<script src="cdpr-report-check.js"></script>' >"$scratch/checked.html"
# Printed on A4 unless the report says otherwise (a later @page wins).
inject "$report" '<style>@page{size:A4}</style>' >"$scratch/report.html"

failures=0
: >"$out/verdict.txt"
for size in 1280,900 794,1123; do
  width=${size%,*}
  dom=$(run_browser --window-size="$size" --virtual-time-budget=5000 --dump-dom "file://$scratch/checked.html" || true)
  verdict=$(sed -n '/<pre id="cdpr-report-check" hidden/,/<\/pre>/p' <<<"$dom" |
            sed -e 's/.*<pre id="cdpr-report-check"[^>]*>//' -e 's/<\/pre>.*//' \
                -e 's/&lt;/</g; s/&gt;/>/g; s/&quot;/"/g; s/&nbsp;/ /g; s/&amp;/\&/g')
  if [[ -z $verdict ]]; then
    verdict="FAIL no verdict: the page did not finish loading or the check did not run (see $out/chromium.log)"
  fi
  awk -v width="$width" '{ print width " px: " $0 }' <<<"$verdict" | tee -a "$out/verdict.txt"
  failures=$((failures + $(grep -c '^FAIL' <<<"$verdict" || true)))
  [[ -z ${CHECK_REPORT_NO_SHOTS:-} ]] || continue
  run_browser --window-size="$size" --screenshot="$out/screen-$width.png" "file://$scratch/report.html" >/dev/null ||
    { echo "FAIL no screenshot at $width px (see $out/chromium.log)" | tee -a "$out/verdict.txt"; failures=$((failures + 1)); }
done
if [[ -z ${CHECK_REPORT_NO_SHOTS:-} ]]; then
  run_browser --no-pdf-header-footer --print-to-pdf="$out/print-a4.pdf" "file://$scratch/report.html" >/dev/null ||
    { echo "FAIL not printed (see $out/chromium.log)" | tee -a "$out/verdict.txt"; failures=$((failures + 1)); }
  if [[ -s $out/print-a4.pdf ]]; then
    echo "A4: $(grep -a -o '/Type */Page\b' "$out/print-a4.pdf" | wc -l) pages" | tee -a "$out/verdict.txt"
  fi
fi

# HTML5 validity: tidy's errors and warnings, line and column of the report.
tidy_out=$(tidy -q -e --drop-empty-elements no --drop-empty-paras no "$report" 2>&1 |
           grep -v 'Warning: <svg> proprietary attribute' | grep -E '(Warning|Error):' || true)
if [[ -n $tidy_out ]]; then
  awk '{ print "FAIL html5: " $0 }' <<<"$tidy_out" | tee -a "$out/verdict.txt"
  failures=$((failures + $(wc -l <<<"$tidy_out")))
fi

if [[ $failures -gt 0 ]]; then
  echo "$report: $failures problems (screenshots, print and verdict in $out)"
  exit 1
fi
echo "$report: passed (screenshots, print and verdict in $out)"
