#!/bin/sh
# Runs `hexcnc interp` on tests/interp_expected/*.ngc and compares its motion lines
# (STRAIGHT_TRAVERSE, STRAIGHT_FEED, STRAIGHT_PROBE, ARC_FEED, NURBS_FEED, DWELL, RIGID_TAP and
# the START_SPEED_FEED_SYNC/STOP_SPEED_FEED_SYNCH around G33), outputs (M62..M68) and active comments
# (MESSAGE, LOG...) with those in NAME.out, which LinuxCNC's
# `rs274 -g NAME.ngc` printed (with -t NAME.tbl when that file exists; rs274 alone reads a
# tool table in inches, so where NAME.rs274.tbl exists, the same tools in inches, rs274 is
# given that one instead). The first column
# (rs274's output line counter) is left out: the two print different non-motion lines.
# With rs274 installed and REGEN=1 the .out files are made again. sub_NAME.ngc files hold
# subroutines (o<sub_NAME> sub) that the programs call: they are found beside the program.
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
dir=$root/tests/interp_expected
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
pass=0; fail=0
# (a zero rs274 prints as -0.0000, about -1e-16 after a last-bit rounding, is the zero it is)
motion() { grep -E 'STRAIGHT_TRAVERSE|STRAIGHT_FEED|STRAIGHT_PROBE|ARC_FEED|NURBS_FEED|DWELL|RIGID_TAP|SPEED_FEED_SYNC|_OUTPUT_(BIT|VALUE)|N\.* (MESSAGE|LOG(OPEN|APPEND|CLOSE)?)\(' |
           cut -c7- | sed -E 's/-(0\.0+)([,)])/\1\2/g'; }
for ngc in "$dir"/*.ngc; do
    name=$(basename "$ngc" .ngc)
    case $name in sub_*) continue ;; esac  # subroutine files that programs here call
    opt=""
    [ -f "$dir/$name.tbl" ] && opt="-t $name.tbl"
    if [ "${REGEN:-0}" = 1 ]; then
        rsopt=$opt
        [ -f "$dir/$name.rs274.tbl" ] && rsopt="-t $name.rs274.tbl"
        (cd "$dir" && rs274 -g $rsopt "$name.ngc" > "$name.out" 2>/dev/null)
    fi
    motion < "$dir/$name.out" > "$tmp/expected"
    if ! (cd "$dir" && "$bin" interp $opt "$name.ngc") > "$tmp/out" 2> "$tmp/err"; then
        echo "FAIL $name: hexcnc interp failed: $(cat "$tmp/err")"
        fail=$((fail + 1))
        continue
    fi
    motion < "$tmp/out" > "$tmp/got"
    if [ ! -s "$tmp/expected" ]; then
        echo "FAIL $name: no motion lines in $name.out"
        fail=$((fail + 1))
    elif diff -u "$tmp/expected" "$tmp/got" > "$tmp/diff"; then
        echo "ok   $name ($(wc -l < "$tmp/expected") motion lines)"
        pass=$((pass + 1))
    else
        echo "FAIL $name: motion lines differ from rs274's:"
        head -20 "$tmp/diff"
        fail=$((fail + 1))
    fi
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
