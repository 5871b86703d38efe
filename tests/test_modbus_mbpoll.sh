#!/bin/sh
# test_modbus_mbpoll.sh: `hexcnc modbus_sim` with a third-party Modbus client, mbpoll (Debian
# package mbpoll). mbpoll opens a new connection for every request: the drives must move on
# wall time between them. Skips, saying why, when mbpoll is not installed.
if ! command -v mbpoll > /dev/null 2>&1; then
    echo "test_modbus_mbpoll.sh: SKIP: mbpoll is not installed (Debian package mbpoll, listed in mk/deps.sh)"
    exit 0
fi
. "$HEXCNC_ROOT/tests/modbus_test_lib.sh"
fail=0
tmp=$(mktemp -d /tmp/test_modbus_mbpoll.XXXXXX) || exit 1
base=$(free_base_port 2) || { echo "no free ports"; exit 1; }
mkfifo "$tmp/in"
timeout 60 "$HEXCNC_BIN" modbus_sim --drives 2 --base-port $base --start 10,-20 \
    < "$tmp/in" > "$tmp/sim.out" 2>&1 &
sim=$!
exec 3> "$tmp/in"                      # keeps the simulator's stdin open
for i in $(seq 1 100); do
    grep -q "positions mm" "$tmp/sim.out" && break
    sleep 0.1
done
if ! grep -q "positions mm" "$tmp/sim.out"; then
    echo "modbus_sim did not start:"; cat "$tmp/sim.out"; exec 3>&-; rm -rf "$tmp"; exit 1
fi

# mbpoll on drive N: one request, 0-based register addresses (-0), 32-bit values high word
# first (-B, the simulator's default word order). mb N REG TYPE [VALUE to write]
mb() { mb_n=$1 mb_r=$2 mb_t=$3; shift 3
       mbpoll -m tcp -p $((base + mb_n)) -0 -B -1 -o 2 -r $mb_r -t $mb_t 127.0.0.1 "$@"; }
# The actual position of drive N (registers 11..12) as mbpoll reads it, or nothing.
actual() { mb "$1" 11 4:int 2> "$tmp/err" | sed -n 's/^\[11\]:[[:space:]]*//p'; }

# The start positions of --start, in counts (1000 counts/mm).
a0=$(actual 0); a1=$(actual 1)
[ "$a0" = 10000 ] && [ "$a1" = -20000 ] ||
    { echo "start: read '$a0' '$a1', want 10000 -20000"; cat "$tmp/err" "$tmp/sim.out"; fail=1; }

# Target 12.5 mm, then ENABLE, each its own connection; the drive gets there on its own time.
mb 0 1 4:int -- 12500 > /dev/null 2>&1 || { echo "mbpoll could not write the target"; fail=1; }
mb 0 0 4 1 > /dev/null 2>&1 || { echo "mbpoll could not write the control word"; fail=1; }
for i in $(seq 1 50); do
    a0=$(actual 0)
    [ "$a0" = 12500 ] && break
    sleep 0.1
done
[ "$a0" = 12500 ] || { echo "drive 0 did not reach 12500 counts: last read '$a0'"; cat "$tmp/err"; fail=1; }
st=$(mb 0 10 4:hex 2> /dev/null | sed -n 's/^\[10\]:[[:space:]]*//p')
[ "$st" = 0x0403 ] || { echo "status word '$st', want 0x0403 (ready, enabled, at target)"; fail=1; }
a1=$(actual 1)
[ "$a1" = -20000 ] || { echo "drive 1 (not enabled) moved to '$a1'"; fail=1; }

# A fault typed on the simulator's stdin reaches mbpoll as Modbus exception 4.
echo "fault 1 exception 4" >&3
for i in $(seq 1 50); do
    grep -q "^drive 1: exception" "$tmp/sim.out" && break
    sleep 0.1
done
if mb 1 11 4:int > /dev/null 2> "$tmp/err" || ! grep -q "Slave device or server failure" "$tmp/err"; then
    echo "exception 4 not seen by mbpoll:"; cat "$tmp/err"; fail=1
fi
echo quit >&3
exec 3>&-
wait $sim || { echo "modbus_sim exited with $?"; fail=1; }
rm -rf "$tmp"
[ $fail -eq 0 ] && echo "test_modbus_mbpoll.sh: mbpoll read, wrote and saw the drive move and fault"
exit $fail
