#!/bin/sh
# test_modbus_cli.sh: `hexcnc modbus_sim` as its own process on loopback, driven by
# `hexcnc halcmd` on the real-time clock (I/O threads), with a fault set from its stdin.
fail=0
tmp=$(mktemp -d /tmp/test_modbus_cli.XXXXXX) || exit 1
base=$((20000 + $$ % 20000))
mkfifo "$tmp/in"
: > "$tmp/sim.out"
"$HEXCNC_BIN" modbus_sim --drives 2 --base-port $base --seconds 20 < "$tmp/in" > "$tmp/sim.out" 2>&1 &
sim=$!
exec 3> "$tmp/in"                      # keeps the simulator's stdin open
for i in 1 2 3 4 5 6 7 8 9 10; do
    grep -q "2 drives" "$tmp/sim.out" && break
    sleep 0.2
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

# Both drives follow their commands through the simulator's lag within 300 ms.
out=$(printf 'source %s\nstart\ngetp modbus.0.position-fb\ngetp modbus.1.position-fb\ngetp modbus.1.fault\n' \
      "$tmp/m.hal" | "$HEXCNC_BIN" halcmd -i "$tmp/m.ini" --run-ms 300 2>&1)
want=$(printf '12.5\n-3.25\nFALSE')
if [ "$out" != "$want" ]; then
    echo "follow: got '$out', want '$want'"; fail=1
fi

# Drive 1 answers with exception 4: its fault pin rises and the message names it.
echo "fault 1 exception 4" >&3
sleep 0.2
out=$(printf 'source %s\nstart\ngetp modbus.0.fault\ngetp modbus.1.fault\n' "$tmp/m.hal" |
      "$HEXCNC_BIN" halcmd -i "$tmp/m.ini" --run-ms 100 2>&1)
want=$(printf 'halcmd: fault: modbus.1: modbus drive 1 (127.0.0.1:%d): exception 4 server device failure at register 0 (write 0..2, read 10..12) (unit 1; at start-up, before its first exchange)\nFALSE\nTRUE' $((base + 1)))
if [ "$out" != "$want" ]; then
    echo "exception: got '$out', want '$want'"; fail=1
fi

echo quit >&3
exec 3>&-
wait $sim || { echo "modbus_sim exited with $?"; fail=1; }
grep -q "drive 1: exception" "$tmp/sim.out" || { echo "no fault echo:"; cat "$tmp/sim.out"; fail=1; }
rm -rf "$tmp"
[ $fail -eq 0 ] && echo "test_modbus_cli.sh: 4 checks passed"
exit $fail
