#!/bin/sh
# jerk_session.sh: the machine session's, probing and rigid-tapping end-to-end runs again on the
# simulated TMU with jerk limits ([TRAJ] MAX_LINEAR_JERK, MAX_ANGULAR_JERK, [JOINT_n] MAX_JERK added to
# a copy of configs/sim): streaming, holds, aborts, M66 and tool waits, MDI, probing and jogs
# behave as without them; a tap follows the spindle as without them (the moving average stands
# aside on synchronised moves). Needs HEXCNC_ROOT and HEXCNC_BIN (make test sets them).
set -u
root=${HEXCNC_ROOT:-.}
py=/usr/bin/python3
[ -x "$py" ] || py=python3
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
cp -r "$root/configs/sim" "$tmp/sim" || exit 1
awk '{ print }
     /^MAX_ANGULAR_ACCELERATION *=/ { print "MAX_LINEAR_JERK = 50000"; print "MAX_ANGULAR_JERK = 30000" }
     /^MAX_ACCELERATION *=/ { print "MAX_JERK = 50000" }' \
    "$root/configs/sim/tmu-hexapod.ini" > "$tmp/sim/tmu-hexapod.ini" || exit 1
[ "$(grep -c 'JERK' "$tmp/sim/tmu-hexapod.ini")" -eq 8 ] || { echo "FAIL jerk keys not added"; exit 1; }
export HEXCNC_SIM_DIR="$tmp/sim"
fail=0
"$py" "$root/tests/e2e/machine_session.py" || fail=1
"$py" "$root/tests/e2e/machine_probe.py" || fail=1
"$py" "$root/tests/e2e/machine_sync.py" || fail=1
# the session again with [TRAJ] JERK_WINDOW the full 40 ms, where the legs keep their 1000
# mm/s^2 (the default, above, is the path's 20 ms, the legs lowered to 500; docs/motion.md)
sed 's/^MAX_LINEAR_JERK = 50000$/&\nJERK_WINDOW = 0.040/' "$tmp/sim/tmu-hexapod.ini" \
    > "$tmp/w.ini" && mv "$tmp/w.ini" "$tmp/sim/tmu-hexapod.ini" || exit 1
[ "$(grep -c '^JERK_WINDOW = 0.040$' "$tmp/sim/tmu-hexapod.ini")" -eq 1 ] ||
    { echo "FAIL JERK_WINDOW not added"; exit 1; }
echo "with [TRAJ] JERK_WINDOW = 0.040:"
"$py" "$root/tests/e2e/machine_session.py" || fail=1
exit $fail
