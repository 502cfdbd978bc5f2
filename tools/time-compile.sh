#!/bin/bash
# Compiler launcher that logs the CPU seconds of each compile:
#   cmake -S . -B build-time -DCMAKE_CXX_COMPILER_LAUNCHER=$PWD/tools/time-compile.sh
#   TIME_COMPILE_LOG=/tmp/tu.txt cmake --build build-time -j2
# Appends "user sys wall output" per translation unit to $TIME_COMPILE_LOG
# (default /tmp/time-compile.txt). Needs /usr/bin/time (Debian: time).
# CPU seconds per target, highest first:
#   awk '{n = split($4, p, "/"); for (i = 1; i <= n; i++) if (p[i] ~ /[.]dir$/) t = p[i];
#        s[t] += $1 + $2} END {for (t in s) print s[t], t}' /tmp/tu.txt | sort -gr
# Anything after the launcher (e.g. ccache) runs as the compiler.
out=""
prev=""
for arg in "$@"; do
  [[ $prev == -o ]] && out=$arg
  prev=$arg
done
times=$(mktemp)
/usr/bin/time -f "%U %S %e" -o "$times" "$@"
status=$?
echo "$(tail -1 "$times") $out" >> "${TIME_COMPILE_LOG:-/tmp/time-compile.txt}"
rm -f "$times"
exit $status
