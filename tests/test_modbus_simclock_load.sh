#!/bin/sh
# test_modbus_simclock_load.sh: configs/modbus-sim on the simulated clock gives the same
# result on every run while CPU hogs load the machine. The drives' TIMEOUT is cut to 0.2 ms
# so that any wall-clock wait on the drives would fault at once under the load: on the
# simulated clock an exchange takes no simulated time, so none may fault.
. "$HEXCNC_ROOT/tests/modbus_test_lib.sh"
fail=0
runs=4
tmp=$(mktemp -d /tmp/test_modbus_simclock_load.XXXXXX) || exit 1
base=$(free_base_port 6) || { echo "no free ports"; exit 1; }
machine_ini "$HEXCNC_ROOT/configs/modbus-sim/tmu-hexapod-modbus.ini" "$tmp/m.ini" "$base" \
    TIMEOUT=0.2
hogs=""
for i in 1 2 3 4; do
    timeout 120 sh -c 'while :; do :; done' &
    hogs="$hogs $!"
done
for r in $(seq 1 $runs); do
    timeout 120 "$HEXCNC_BIN" run --sim-clock "$tmp/m.ini" > "$tmp/out$r" 2>&1
    rc=$?
    # Only the computer time of the run may differ.
    sed -i 's/simulated in .*$/simulated in (computer time)/' "$tmp/out$r"
    if [ $rc -ne 0 ] || ! grep -q "^program finished" "$tmp/out$r" || grep -qi fault "$tmp/out$r"; then
        echo "run $r: exit $rc:"; cat "$tmp/out$r"; fail=1
    elif ! cmp -s "$tmp/out1" "$tmp/out$r"; then
        echo "run $r differs from run 1:"; diff "$tmp/out1" "$tmp/out$r"; fail=1
    fi
done
kill $hogs 2>/dev/null
wait 2>/dev/null
grep -q "final legs mm" "$tmp/out1" || { echo "no summary:"; cat "$tmp/out1"; fail=1; }
rm -rf "$tmp"
[ $fail -eq 0 ] && echo "test_modbus_simclock_load.sh: $runs runs under load, identical, no fault"
exit $fail
