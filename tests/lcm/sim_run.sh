#!/bin/sh
# sim_run.sh: `hexcnc run` of the paper's program (10) on the simulated machine publishes its
# status through configs/sim/lcm-status.hal: the sim config is copied with [LCM] URL turned
# into a file:// log, and the log is checked (lcm_check --run): samples every 50 ms of machine
# time (RATE_HZ = 20), numbered without gaps, running, feedback following the command.
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
check=${HEXCNC_BUILD:-$root/build}/tests/lcm/lcm_check
[ -x "$check" ] || { echo "FAIL sim_run.sh: $check is not built"; exit 1; }
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT

# The paper's program runs on the paper's machine (F in m/min): its INI with the relative paths
# made absolute, beside the copy of configs/sim's HAL files.
cp "$root"/configs/sim/* "$tmp/"
sed "s|^URL = .*|URL = file://$tmp/run.lcmlog?mode=w|; s|^RATE_HZ = .*|RATE_HZ = 20|; s|= \.\./\.\./\.\./configs/sim/|= $tmp/|" \
    "$root/examples/paper/experiment/tmu-path1.ini" > "$tmp/tmu-hexapod.ini"
if ! timeout 120 "$bin" run --quiet --sim-clock "$tmp/tmu-hexapod.ini" \
        "$root/examples/paper/prog10_g141_d20.ngc" > "$tmp/run.out" 2>&1; then
    echo "FAIL sim_run.sh: hexcnc run failed:"; cat "$tmp/run.out"; exit 1
fi
"$check" --run "$tmp/run.lcmlog" 50
