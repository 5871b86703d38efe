#!/bin/sh
# test_modbus_two_process.sh: the two-process setup of docs/modbus.md on loopback. One
# process serves the six drives (`hexcnc modbus_sim --ini ... --lockstep`), another runs the
# paper's program (10) on them (`hexcnc run --sim-clock configs/modbus-sim/
# tmu-hexapod-modbus-external.ini`): it runs to its end and matches, line for line, the run
# with the drives simulated in-process (configs/modbus-sim/tmu-hexapod-modbus.ini).
. "$HEXCNC_ROOT/tests/modbus_test_lib.sh"
fail=0
tmp=$(mktemp -d /tmp/test_modbus_two_process.XXXXXX) || exit 1
base=$(free_base_port 12) || { echo "no free ports"; exit 1; }
cfg="$HEXCNC_ROOT/configs/modbus-sim"
machine_ini "$cfg/tmu-hexapod-modbus-external.ini" "$tmp/ext.ini" "$base"
machine_ini "$cfg/tmu-hexapod-modbus.ini" "$tmp/inproc.ini" $((base + 6))

mkfifo "$tmp/in"
timeout 120 "$HEXCNC_BIN" modbus_sim --ini "$tmp/ext.ini" --lockstep < "$tmp/in" \
    > "$tmp/sim.out" 2>&1 &
sim=$!
exec 3> "$tmp/in"                      # keeps the simulator's stdin open
for i in $(seq 1 100); do
    grep -q "positions mm" "$tmp/sim.out" && break
    sleep 0.1
done
# Parked at the leg lengths of [KINS] HOME (0 0 645 0 0 0).
want="modbus_sim: positions mm: 725.4045 725.4045 725.4045 725.4045 725.4045 725.4045"
if ! grep -q "^modbus_sim: 6 drives on 127.0.0.1:$base..$((base + 5)) " "$tmp/sim.out" ||
   ! grep -qx "$want" "$tmp/sim.out"; then
    echo "modbus_sim --ini did not start as expected:"; cat "$tmp/sim.out"; fail=1
fi

timeout 120 "$HEXCNC_BIN" run --sim-clock "$tmp/ext.ini" > "$tmp/ext.out" 2>&1
rc=$?
if [ $rc -ne 0 ] || ! grep -q "^program finished" "$tmp/ext.out" || grep -qi fault "$tmp/ext.out"; then
    echo "run on the other process's drives: exit $rc:"; cat "$tmp/ext.out"; fail=1
fi
timeout 120 "$HEXCNC_BIN" run --sim-clock "$tmp/inproc.ini" > "$tmp/inproc.out" 2>&1
# The same machine and drives: only the INI's name and the computer time may differ.
for f in ext inproc; do
    sed -e 1d -e 's/simulated in .*$//' "$tmp/$f.out" > "$tmp/$f.cmp"
done
if ! cmp -s "$tmp/ext.cmp" "$tmp/inproc.cmp"; then
    echo "two processes vs in-process:"; diff "$tmp/ext.cmp" "$tmp/inproc.cmp"; fail=1
fi
grep -q "0.0066 mm from the commanded end" "$tmp/ext.out" ||
    { echo "end point:"; cat "$tmp/ext.out"; fail=1; }

# One connection per drive for the whole program, one exchange every 4 ms of its 4.97 s.
echo state >&3
for i in $(seq 1 50); do
    [ "$(grep -c "^drive [0-5] port" "$tmp/sim.out")" -eq 6 ] && break
    sleep 0.1
done
n=$(grep "^drive [0-5] port" "$tmp/sim.out" | grep -c "12[45][0-9] requests, 1 connections")
[ "$n" -eq 6 ] || { echo "state:"; cat "$tmp/sim.out"; fail=1; }
echo quit >&3
exec 3>&-
wait $sim || { echo "modbus_sim exited with $?"; fail=1; }
rm -rf "$tmp"
[ $fail -eq 0 ] && echo "test_modbus_two_process.sh: the paper's program ran on drives in another process"
exit $fail
