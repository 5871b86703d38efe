#!/bin/sh
# run_cli.sh: `hexcnc run` and scripts/hexcnc-start as a machinist uses them: the paper's
# program to its end, refusals before any motion (exit 1 with file:line), Ctrl-C (exit 130).
# Needs HEXCNC_ROOT and HEXCNC_BIN (make test sets them).
set -u
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
start="$root/scripts/hexcnc-start"
# The paper's machine for path 1: F in m/min as the paper's programs write it (configs/sim
# reads mm/min), HAL files and tool table of configs/sim.
ini="$root/examples/paper/experiment/tmu-path1.ini"
tmp=$(mktemp -d /tmp/hexcnc-run-cli.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
export HEXCNC_BIN="$bin"
fails=0

# check NAME CONDITION...: prints ok/FAIL for one expectation.
check() {
    name=$1; shift
    if "$@"; then echo "ok   $name"; else echo "FAIL $name"; fails=$((fails + 1)); fi
}
has() { grep -q -- "$2" "$1"; }

# 1. The paper's program (10) runs to its end on the simulated clock.
sh "$start" "$ini" "$root/examples/paper/prog10_g141_d20.ngc" >"$tmp/out" 2>"$tmp/err"
rc=$?
check "program (10) exits 0" [ $rc -eq 0 ]
check "summary printed" has "$tmp/out" "machine time"
check "program finished" has "$tmp/out" "program finished"
check "ends at the compensated end point of paper.md" has "$tmp/out" "commanded end  X 59.975641  Y -20.000000  Z 630.697565"

# 2. A missing INI file is refused by the script.
sh "$start" "$tmp/none.ini" >"$tmp/out" 2>"$tmp/err"
check "missing INI exits 1" [ $? -eq 1 ]
check "missing INI named" has "$tmp/err" "cannot find the INI file"

# 3. A malformed program: the interpreter's file:line, no motion, exit 1.
printf 'G1 X10 Y0 Z640 F2\nG1 X1 Y=\nM2\n' >"$tmp/bad.ngc"
"$bin" run "$ini" "$tmp/bad.ngc" >"$tmp/out" 2>"$tmp/err"
check "malformed program exits 1" [ $? -eq 1 ]
check "malformed program names file:line" has "$tmp/err" "bad.ngc:2"
check "malformed program: no motion" has "$tmp/err" "did not move"

# 4. A point out of reach is refused before motion, naming its line.
printf 'G1 X0 Y0 Z645 F2\nG1 X10\nG1 X600\nM2\n' >"$tmp/far.ngc"
"$bin" run "$ini" "$tmp/far.ngc" >"$tmp/out" 2>"$tmp/err"
check "unreachable point exits 1" [ $? -eq 1 ]
check "unreachable point names line 3" has "$tmp/err" "far.ngc:3"

# 5. A HAL file error names the HAL file and line.
printf 'loadrt stepgen count=6\nnet leg-0-cmd nosuch.pin\n' >"$tmp/broken.hal"
sed "s|^HALFILE = .*|HALFILE = $tmp/broken.hal|; s|^TOOL_TABLE = \.\./\.\./\.\./|TOOL_TABLE = $root/|" \
    "$ini" >"$tmp/broken.ini"
"$bin" run "$tmp/broken.ini" "$tmp/far.ngc" >"$tmp/out" 2>"$tmp/err"
check "HAL error exits 1" [ $? -eq 1 ]
check "HAL error names file:line" has "$tmp/err" "broken.hal:2"

# 6. Without the task's e-stop wiring the machine stays in e-stop: said at once, not hung.
grep -v "^HALFILE = .*tmu-hexapod-task.hal" "$ini" | sed "s|^HALFILE = \.\./\.\./\.\./|HALFILE = $root/|" \
    | sed "s|^TOOL_TABLE = \.\./\.\./\.\./|TOOL_TABLE = $root/|" >"$tmp/noreset.ini"
"$bin" run "$tmp/noreset.ini" "$root/examples/paper/prog10_g141_d20.ngc" >"$tmp/out" 2>"$tmp/err"
check "held in e-stop exits 3" [ $? -eq 3 ]
check "held in e-stop says so" has "$tmp/err" "did not come out of e-stop"

# 7. Ctrl-C on a real-time run: controlled stop, summary, exit 130.
sh "$start" --realtime "$ini" "$root/examples/paper/prog10_g141_d20.ngc" >"$tmp/out" 2>"$tmp/err" &
pid=$!
sleep 1
kill -INT $pid
wait $pid
rc=$?
check "Ctrl-C exits 130" [ $rc -eq 130 ]
check "Ctrl-C says it stopped" has "$tmp/err" "interrupted"
check "Ctrl-C still prints the summary" has "$tmp/out" "machine time"

[ $fails -eq 0 ] || { echo "run_cli: $fails failed"; cat "$tmp/err"; exit 1; }
echo "run_cli: all passed"
