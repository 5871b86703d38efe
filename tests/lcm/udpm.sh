#!/bin/sh
# udpm.sh: lcm-status over real UDP multicast, inside a private network namespace (so it needs
# no multicast route on the machine and disturbs nothing): hexcnc halcmd publishes
# tests/lcm/publish.hal on the simulated clock while lcm_check listens live and lcm-logger
# records; then the recorded log is read back and decoded. SKIPs (exit 0) where network
# namespaces are not permitted.
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
check=${HEXCNC_BUILD:-$root/build}/tests/lcm/lcm_check
url='udpm://239.255.76.67:7667?ttl=0'
count=21         # 1 s at 20 Hz: a sample at 1 ms, then every 50 ms up to 1000 ms

if ! unshare -n true 2>/dev/null; then
    echo "SKIP udpm.sh: 'unshare -n' is not permitted here (needs root or user namespaces)"
    exit 0
fi
if ! command -v lcm-logger >/dev/null 2>&1; then
    echo "SKIP udpm.sh: lcm-logger not found (Debian package liblcm-bin)"
    exit 0
fi
[ -x "$check" ] || { echo "FAIL udpm.sh: $check is not built"; exit 1; }
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT

# Inside the namespace: loopback up with a multicast route; logger and listener first, then
# the publisher; the listener's exit status comes out through a file.
unshare -n sh -c '
    ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo || exit 3
    lcm-logger -f --lcm-url="$1" "$2/run.lcmlog" > "$2/logger.out" 2>&1 & logger=$!
    "$3" --listen "$1" "$4" 10000 > "$2/listen.out" 2>&1 & listener=$!
    sleep 0.5
    "$5" halcmd -i "$6/tests/lcm/udpm.ini" -s --run-ms 1000 -f "$6/tests/lcm/publish.hal" \
        > "$2/publish.out" 2>&1 || echo "publisher failed" >> "$2/publish.out"
    wait $listener; echo $? > "$2/listen.rc"
    sleep 0.3
    kill -INT $logger; wait $logger
' sh "$url" "$tmp" "$check" "$count" "$bin" "$root"
rc=$?
if [ $rc -eq 3 ]; then
    echo "SKIP udpm.sh: cannot bring up loopback or add a multicast route in the namespace"
    exit 0
fi

fail=0
if [ -s "$tmp/publish.out" ]; then
    echo "FAIL udpm.sh: the publisher said:"; cat "$tmp/publish.out"; fail=1
fi
if [ "$(cat "$tmp/listen.rc" 2>/dev/null)" != 0 ]; then
    echo "FAIL udpm.sh: live subscriber:"; cat "$tmp/listen.out"; fail=1
else
    tail -n 1 "$tmp/listen.out"
fi
if ! "$check" "$tmp/run.lcmlog" "$count"; then
    echo "lcm-logger said:"; cat "$tmp/logger.out"; fail=1
fi
[ $fail -eq 0 ] && echo "udpm.sh: multicast publish, live subscriber and lcm-logger log checked"
exit $fail
