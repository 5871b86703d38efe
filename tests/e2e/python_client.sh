#!/bin/sh
# python_client.sh: python/hexcnc_client.py's unit tests (a scripted server), then the client
# and python/pendant_example.py against a real `hexcnc machine` on the simulated clock:
# switched on, homed, stepped along X and along the tool, an MDI line, a refused key, and
# the poses it prints. Needs HEXCNC_ROOT and HEXCNC_BIN (make test sets them).
set -u
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
py=/usr/bin/python3
[ -x "$py" ] || py=python3
tmp=$(mktemp -d /tmp/hexcnc-pyclient.XXXXXX)
pid=""
cleanup() {
    [ -n "$pid" ] && kill "$pid" 2>/dev/null
    rm -rf "$tmp"
}
trap cleanup EXIT
fails=0
check() {
    name=$1; shift
    if "$@"; then echo "ok   $name"; else echo "FAIL $name"; fails=$((fails + 1)); fi
}
has() { grep -q -- "$2" "$1"; }

"$py" "$root/python/test_hexcnc_client.py" >"$tmp/unit" 2>&1
check "hexcnc_client unit tests" [ $? -eq 0 ]
tail -n 3 "$tmp/unit"

sock=$tmp/m.sock
"$bin" machine --sim-clock --quiet --socket "$sock" "$root/configs/sim/tmu-hexapod.ini" &
pid=$!
i=0
while [ ! -S "$sock" ] && [ $i -lt 500 ]; do sleep 0.01; i=$((i + 1)); done
check "session listening" [ -S "$sock" ]

cat >"$tmp/keys" <<'KEYS'
X+
where
on
home
step 2.5
X+
X+
where
T-
where
mdi G0 X0 Y0 Z650 A0 B0 C0
where
KEYS
"$py" "$root/python/pendant_example.py" --socket "$sock" --step 1 --speed 20 \
    <"$tmp/keys" >"$tmp/out" 2>"$tmp/err"
rc=$?
check "the pendant reports the refused key (exit 1)" [ $rc -eq 1 ]
check "... the jog before the machine is on, with the session's reason" \
    has "$tmp/err" "refused: jog refused: the machine is in e-stop"
check "two steps of 2.5 mm after homing: X 5" \
    sh -c "sed -n 2p '$tmp/out' | grep -q '^X 5.0000 Y 0.0000 Z 645.0000 A 0.0000 B 0.0000 C 0.0000$'"
check "a tool step down (vertical tool): Z 642.5" \
    sh -c "sed -n 3p '$tmp/out' | grep -q '^X 5.0000 Y 0.0000 Z 642.5000 '"
check "the MDI line reached its point" \
    sh -c "sed -n 4p '$tmp/out' | grep -q '^X 0.0000 Y 0.0000 Z 650.0000 A 0.0000 B 0.0000 C 0.0000$'"

# halcmd on the running machine, through the same API
"$bin" halcmd --attach "$sock" show 'motion.feed*' >"$tmp/show" 2>&1
check "halcmd --attach show: the running machine's pins" has "$tmp/show" "motion.feed-override"
"$bin" halcmd --attach "$sock" setp motion.feed-override 0.75 &&
    "$bin" halcmd --attach "$sock" getp motion.feed-override >"$tmp/getp" 2>&1
check "halcmd --attach setp, then getp: 0.75" [ "$(cat "$tmp/getp")" = "0.75" ]
"$bin" halcmd --attach "$sock" loadrt stepgen >"$tmp/out2" 2>"$tmp/err2"
check "halcmd --attach refuses what a running machine cannot do (exit 2)" [ $? -eq 2 ]
check "... and says what it can" has "$tmp/err2" "only show"
"$bin" halcmd --attach "$sock" getp no.such.pin >"$tmp/out2" 2>"$tmp/err2"
rc=$?
check "halcmd --attach getp of an unknown name: exit 1" [ $rc -eq 1 ]
check "... naming it" has "$tmp/err2" "no.such.pin"

"$py" - "$root/python" "$sock" >"$tmp/shut" 2>&1 <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import hexcnc_client as hc
with hc.Client(sys.argv[2]) as m:
    st = m.status()
    assert st["state"] == "on" and all(st["homed"]), st
    m.shutdown()
print("shut down")
PY
check "the client shuts the session down" has "$tmp/shut" "shut down"
wait "$pid"
check "session exited 0" [ $? -eq 0 ]
pid=""

if [ "$fails" -ne 0 ]; then
    echo "python_client: $fails failed"; cat "$tmp/out" "$tmp/err"
    exit 1
fi
echo "python_client: all passed"
