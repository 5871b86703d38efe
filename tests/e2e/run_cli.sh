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

# 3b. G38 probing: `hexcnc run` plans the whole program first, so it refuses, naming the line.
printf 'G21 G90 F300\nG1 X1 Y0 Z640\nG38.2 Z600\nM2\n' >"$tmp/probe.ngc"
"$bin" run "$ini" "$tmp/probe.ngc" >"$tmp/out" 2>"$tmp/err"
check "G38 in hexcnc run exits 1" [ $? -eq 1 ]
check "G38 in hexcnc run names file:line and the session" has "$tmp/err" "probe.ngc:3:1: error: G38.2: .hexcnc run. plans the whole program"
check "G38 in hexcnc run: no motion" has "$tmp/err" "did not move"

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

# 8. Settings G-code writes (G10 L1 tool table, G10 L2 parameter file) are saved only when
#    their line runs on the machine: interp and check leave both files byte for byte as they
#    were, and so does a run refused before motion; a full run saves them.
m="$tmp/settings"; mkdir -p "$m"
sed "s|^HALFILE = \.\./\.\./\.\./|HALFILE = $root/|" "$ini" \
    | sed "s|^TOOL_TABLE = .*|TOOL_TABLE = $m/tool.tbl\nPARAMETER_FILE = $m/hexcnc.var|" >"$m/m.ini"
printf 'T1 P1 D10 ;ten\n' >"$m/tool.tbl"
printf '5221\t0.000000\n' >"$m/hexcnc.var"
printf 'G0 X0 Y0 Z645\nG10 L1 P1 R7\nG10 L2 P1 X0.5\nG1 X10 F2\nM2\n' >"$m/g10.ngc"
sums() { cksum "$m/tool.tbl" "$m/hexcnc.var"; }
sums >"$m/before"
"$bin" interp -i "$m/m.ini" "$m/g10.ngc" >"$tmp/out" 2>"$tmp/err"
check "interp of a G10 program exits 0" [ $? -eq 0 ]
sums | cmp -s - "$m/before"; check "interp leaves tool table and parameter file as they were" [ $? -eq 0 ]
"$bin" check "$m/m.ini" "$m/g10.ngc" >"$tmp/out" 2>"$tmp/err"
check "check of a G10 program exits 0" [ $? -eq 0 ]
sums | cmp -s - "$m/before"; check "check leaves tool table and parameter file as they were" [ $? -eq 0 ]
printf 'G0 X0 Y0 Z645\nG10 L1 P1 R7\nG10 L2 P1 X0.5\nG1 X600 F2\nM2\n' >"$m/far.ngc"
"$bin" run "$m/m.ini" "$m/far.ngc" >"$tmp/out" 2>"$tmp/err"
check "refused G10 program exits 1" [ $? -eq 1 ]
sums | cmp -s - "$m/before"; check "refused run leaves tool table and parameter file as they were" [ $? -eq 0 ]
"$bin" run "$m/m.ini" "$m/g10.ngc" >"$tmp/out" 2>"$tmp/err"
check "G10 program runs" [ $? -eq 0 ]
check "the run saved G10 L1 (T1 D14)" has "$m/tool.tbl" "^T1 P1 D14 ;ten"
check "the run saved G10 L2 (#5221 = 0.5)" has "$m/hexcnc.var" "^5221.0.500000"

# 9. A %-framed program cut short (no closing %) is refused before motion, with file:line.
printf '%%\nG0 X0 Y0 Z645\nG1 X15 F2\nG1 X1' >"$tmp/cut.ngc"
"$bin" run "$ini" "$tmp/cut.ngc" >"$tmp/out" 2>"$tmp/err"
check "truncated program exits 1" [ $? -eq 1 ]
check "truncated program names file:line" has "$tmp/err" "cut.ngc:4: error: the program opened with '%' on line 1 ends without its closing '%'"
check "truncated program: no motion" has "$tmp/err" "did not move"

# 10. A machine that is not at HOME (simulated legs started 5 mm short on leg 1 ... 0.4 mm
#     on leg 6): the program is planned from where the legs are and runs to its end (it
#     stopped on a following error of 5.4 mm in its first period while runs were planned
#     from [KINS] HOME).
mkdir -p "$tmp/away"
cp -r "$root/configs/sim/." "$tmp/away/"
for i in 0 1 2 3 4 5; do echo "setp stepgen.$i.sim-start $((720 + i))"; done \
    >>"$tmp/away/tmu-hexapod.hal"
"$bin" run --sim-clock "$tmp/away/tmu-hexapod.ini" >"$tmp/out" 2>"$tmp/err"
check "away from HOME: the program runs to its end (exit 0)" [ $? -eq 0 ]
check "away from HOME: no following error" sh -c "! grep -q 'following error' '$tmp/err'"
check "away from HOME: finished at its end point" has "$tmp/out" \
    "commanded end  X 0.000000  Y 0.000000  Z 645.000000"

[ $fails -eq 0 ] || { echo "run_cli: $fails failed"; cat "$tmp/err"; exit 1; }
echo "run_cli: all passed"
