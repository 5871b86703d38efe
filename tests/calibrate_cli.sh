#!/bin/sh
# calibrate_cli.sh: `hexcnc calibrate plan` and `fit` as a user runs them: planned poses
# within the leg limits, a "real" TMU machine (leg offsets, raised base plane) measured at
# them with `hexcnc kins`, the fit's calibrated INI giving the real machine's leg lengths,
# malformed rows named by file and line, no file changed unless asked, --force.
fail=0
tmp=$(mktemp -d /tmp/calibrate_cli.XXXXXX) || exit 1
trap 'rm -rf "$tmp"' EXIT
ini="$HEXCNC_ROOT/configs/sim/tmu-hexapod.ini"
no() { echo "FAIL: $*"; fail=1; }

"$HEXCNC_BIN" calibrate plan "$ini" 30 -o "$tmp/poses.csv" 2> "$tmp/plan.err" ||
    no "plan failed: $(cat "$tmp/plan.err")"
grep -q "30 poses, condition number of the identification [0-9.]*, written to" "$tmp/plan.err" ||
    no "plan: no condition number: $(cat "$tmp/plan.err")"
[ "$(grep -v '^#' "$tmp/poses.csv" | head -1)" = "X,Y,Z,A,B,C" ] || no "plan: header"
[ "$(grep -v '^#' "$tmp/poses.csv" | wc -l)" -eq 31 ] || no "plan: not 30 poses"
"$HEXCNC_BIN" calibrate plan "$ini" 30 -o "$tmp/poses.csv" 2> "$tmp/again.err" &&
    no "plan replaced an existing file without --force"
grep -q "poses.csv: exists; give --force" "$tmp/again.err" || no "plan: $(cat "$tmp/again.err")"

# The real machine: the nominal INI with leg offsets and the base plane 0.4 mm up.
sed -e 's/^BASE_Z = 0$/BASE_Z = 0.4/' \
    -e 's/^\[KINS\]$/[KINS]\nLEG_OFFSET = 0.3 -0.2 0.1 0.4 -0.5 0.25/' "$ini" > "$tmp/real.ini"
echo "L1,L2,L3,L4,L5,L6,X,Y,Z,A,B,C" > "$tmp/meas.csv"
grep -v '^#' "$tmp/poses.csv" | tail -n +2 | tr ',' ' ' | while read -r x y z a b c; do
    legs=$("$HEXCNC_BIN" kins "$tmp/real.ini" inverse $x $y $z $a $b $c) ||
        { no "pose $x $y $z $a $b $c unreachable"; break; }
    echo "$legs,$x,$y,$z,$a,$b,$c" | tr ' ' ',' >> "$tmp/meas.csv"
done
sum_before=$(cat "$ini" "$tmp/meas.csv" | cksum)
"$HEXCNC_BIN" calibrate fit "$ini" "$tmp/meas.csv" > "$tmp/look.out" 2>&1 ||
    no "fit failed: $(cat "$tmp/look.out")"
grep -q "^total: 30 measurements, 0 outliers" "$tmp/look.out" || no "fit: $(tail -3 "$tmp/look.out")"
[ "$(ls "$tmp" | wc -l)" -eq 6 ] || no "fit without -o wrote a file: $(ls "$tmp")"
"$HEXCNC_BIN" calibrate fit "$ini" "$tmp/meas.csv" -o "$tmp/cal.ini" > "$tmp/fit.out" 2>&1 ||
    no "fit -o failed: $(cat "$tmp/fit.out")"
[ "$(cat "$ini" "$tmp/meas.csv" | cksum)" = "$sum_before" ] || no "fit changed its inputs"
ls "$tmp"/cal.ini.* > /dev/null 2>&1 && no "a temporary was left behind"
# The calibrated INI, as it is, gives the real machine's leg lengths (to 1e-6 mm).
for pose in "0 0 645 0 0 0" "100 -80 630 8 -6 12" "-110 90 665 -9 9 -14"; do
    want=$("$HEXCNC_BIN" kins "$tmp/real.ini" inverse $pose)
    got=$("$HEXCNC_BIN" kins "$tmp/cal.ini" inverse $pose) || no "cal.ini: $got"
    echo "$want $got" | awk '{ for (i = 1; i <= 6; i++) { d = $i - $(i + 6); if (d < 0) d = -d;
        if (d > 1e-6) { print "leg " i " off by " d " mm"; exit 1 } } }' || no "pose $pose"
done
grep -q "^# before calibration: BASE_RADIUS = 500" "$tmp/cal.ini" || no "old geometry kept?"
"$HEXCNC_BIN" calibrate fit "$ini" "$tmp/meas.csv" -o "$tmp/cal.ini" > /dev/null 2> "$tmp/e" &&
    no "fit replaced cal.ini without --force"
grep -q "cal.ini: exists; give --force" "$tmp/e" || no "fit: $(cat "$tmp/e")"
"$HEXCNC_BIN" calibrate fit "$ini" "$tmp/meas.csv" -o "$ini" --force > /dev/null 2> "$tmp/e" &&
    no "fit overwrote its input INI"
grep -q "is the input file" "$tmp/e" || no "fit -o input: $(cat "$tmp/e")"
"$HEXCNC_BIN" calibrate fit "$ini" "$tmp/meas.csv" -o "$tmp/cal.ini" --force > /dev/null 2>&1 ||
    no "fit --force failed"
# A malformed row: the file and line are named, nothing is written.
sed '5s/,[^,]*$/,abc/' "$tmp/meas.csv" > "$tmp/bad.csv"
"$HEXCNC_BIN" calibrate fit "$ini" "$tmp/bad.csv" -o "$tmp/bad.ini" > /dev/null 2> "$tmp/e" &&
    no "a malformed row was accepted"
grep -q "bad.csv:5: C: 'abc' is not a number" "$tmp/e" || no "malformed: $(cat "$tmp/e")"
[ -e "$tmp/bad.ini" ] && no "a failed fit wrote its output"
head -6 "$tmp/meas.csv" > "$tmp/few.csv"
"$HEXCNC_BIN" calibrate fit "$ini" "$tmp/few.csv" > /dev/null 2> "$tmp/e" && no "5 rows accepted"
grep -q "5 measurements: the fit needs at least 8" "$tmp/e" || no "few: $(cat "$tmp/e")"
[ $fail -eq 0 ] && echo "calibrate_cli: ok"
exit $fail
