#!/bin/sh
# bench_servo_runs.sh: `make bench` is not part of `make test`, so a bench could stop working
# unseen (bench_servo did, when the gouge check began refusing its G142 programs as they
# were written). `make test` builds every bench (so each compiles, with the warnings as
# errors in CI); this runs the quick one that goes through the runner end to end, the
# paper's G141 and G142 programs on configs/sim, and checks it ran them all and printed its
# figures. Run by `make test` (HEXCNC_BUILD, HEXCNC_ROOT, HEXCNC_PLUGIN_DIR set).
root=${HEXCNC_ROOT:-.}
build=${HEXCNC_BUILD:-$root/build}
out=$(mktemp) || exit 1
trap 'rm -f "$out"' EXIT
cd "$root" || exit 1
if ! "$build/bench/bench_servo" > "$out" 2>&1; then
    echo "FAIL bench_servo exited with an error:"
    cat "$out"
    exit 1
fi
fail=0
for want in 'paper programs (10) and (11), G141 and G142: 16687 servo periods' \
            'sim config (e-stop + motion + stepgen + kins.forward):' \
            'simulated clock, as hexcnc run: 16.687 s of machine time'; do
    if ! grep -qF "$want" "$out"; then
        echo "FAIL bench_servo printed no line with: $want"
        fail=1
    fi
done
[ $fail -eq 0 ] && echo "ok   bench_servo ran the paper's four programs (16687 periods)"
[ $fail -eq 0 ] || cat "$out"
exit $fail
