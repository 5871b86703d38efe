#!/bin/sh
# test_modbus_cli.sh: `hexcnc modbus_sim` as its own process on loopback, driven by
# `hexcnc halcmd` on the real-time clock (I/O threads), with a fault set from its stdin;
# --help, --start, and commands that arrive together all acted on at once.
. "$HEXCNC_ROOT/tests/modbus_test_lib.sh"
fail=0
checks=0
tmp=$(mktemp -d /tmp/test_modbus_cli.XXXXXX) || exit 1
base=$(free_base_port 2) || { echo "no free ports"; exit 1; }

# --help: usage on stdout, nothing on stderr, exit 0.
"$HEXCNC_BIN" modbus_sim --help > "$tmp/help.out" 2> "$tmp/help.err"
rc=$?
if [ $rc -ne 0 ] || ! grep -q "^usage: hexcnc modbus_sim" "$tmp/help.out" || [ -s "$tmp/help.err" ]; then
    echo "--help: exit $rc, stdout:"; cat "$tmp/help.out"; echo "stderr:"; cat "$tmp/help.err"; fail=1
fi
checks=$((checks + 1))
# A bad value is refused with the option named, exit 2.
"$HEXCNC_BIN" modbus_sim --start 1,2,3 --drives 2 --seconds 1 > "$tmp/bad.out" 2>&1 < /dev/null
rc=$?
if [ $rc -ne 2 ] || ! grep -q -- "--start 1,2,3: expected 2 positions in mm" "$tmp/bad.out"; then
    echo "--start with 3 values for 2 drives: exit $rc:"; cat "$tmp/bad.out"; fail=1
fi
checks=$((checks + 1))

mkfifo "$tmp/in"
: > "$tmp/sim.out"
"$HEXCNC_BIN" modbus_sim --drives 2 --base-port $base --start 7.5,-1.25 --seconds 20 \
    < "$tmp/in" > "$tmp/sim.out" 2>&1 &
sim=$!
exec 3> "$tmp/in"                      # keeps the simulator's stdin open
for i in $(seq 1 50); do
    grep -q "positions mm" "$tmp/sim.out" && break
    sleep 0.1
done
if ! grep -q "modbus_sim: 2 drives on 127.0.0.1:$base..$((base + 1))" "$tmp/sim.out"; then
    echo "modbus_sim did not start:"; cat "$tmp/sim.out"; fail=1
fi
cat > "$tmp/m.ini" <<EOF
[MODBUS]
DRIVES = 2
BASE_PORT = $base
COUNTS_PER_MM = 1000
SETPOINT_PERIOD = 2000000
TIMEOUT = 50
EOF
cat > "$tmp/m.hal" <<EOF
newthread servo-thread 1000000
loadrt modbus
addf modbus.update servo-thread
setp modbus.0.enable 1
setp modbus.1.enable 1
setp modbus.0.position-cmd 12.5
setp modbus.1.position-cmd -3.25
EOF

if ! grep -q "^modbus_sim: positions mm: 7.5000 -1.2500$" "$tmp/sim.out"; then
    echo "--start: no 'positions mm: 7.5000 -1.2500':"; cat "$tmp/sim.out"; fail=1
fi
checks=$((checks + 1))

# Two commands in one write are both acted on at once, with no more input coming.
printf 'position 1 -3.25\nstate\n' >&3
for i in $(seq 1 50); do
    grep -q "^drive 1 port" "$tmp/sim.out" && break
    sleep 0.1
done
if ! grep -q "^drive 1: at -3.2500 mm$" "$tmp/sim.out" ||
   ! grep -q "^drive 1 port $((base + 1)): target -3250 actual -3250.0 counts (-3.2500 mm)" "$tmp/sim.out"; then
    echo "two commands at once: not both answered within 5 s:"; cat "$tmp/sim.out"; fail=1
fi
checks=$((checks + 1))

# Both drives follow their commands through the simulator's lag within 300 ms.
out=$(printf 'source %s\nstart\ngetp modbus.0.position-fb\ngetp modbus.1.position-fb\ngetp modbus.1.fault\n' \
      "$tmp/m.hal" | "$HEXCNC_BIN" halcmd -i "$tmp/m.ini" --run-ms 300 2>&1)
want=$(printf '12.5\n-3.25\nFALSE')
if [ "$out" != "$want" ]; then
    echo "follow: got '$out', want '$want'"; fail=1
fi
checks=$((checks + 1))

# Drive 1 answers with exception 4: its fault pin rises and the message names it.
echo "fault 1 exception 4" >&3
sleep 0.2
out=$(printf 'source %s\nstart\ngetp modbus.0.fault\ngetp modbus.1.fault\n' "$tmp/m.hal" |
      "$HEXCNC_BIN" halcmd -i "$tmp/m.ini" --run-ms 100 2>&1)
want=$(printf 'halcmd: fault: modbus.1: modbus drive 1 (127.0.0.1:%d): exception 4 server device failure at register 0 (write 0..2, read 10..12) (unit 1; at start-up, before its first exchange)\nFALSE\nTRUE' $((base + 1)))
if [ "$out" != "$want" ]; then
    echo "exception: got '$out', want '$want'"; fail=1
fi
checks=$((checks + 1))

echo quit >&3
exec 3>&-
wait $sim || { echo "modbus_sim exited with $?"; fail=1; }
grep -q "drive 1: exception" "$tmp/sim.out" || { echo "no fault echo:"; cat "$tmp/sim.out"; fail=1; }
rm -rf "$tmp"
checks=$((checks + 2))
[ $fail -eq 0 ] && echo "test_modbus_cli.sh: $checks checks passed"
exit $fail
