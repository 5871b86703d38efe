#!/bin/sh
# The sample configurations teach the right thing: configs/sim reads F in mm/min as
# RS274/NGC does, the paper's programs keep F2 = 2 m/min through the paper's own INI files,
# and every program `make run` cuts with G141/G142 runs on an INI whose tool axis is the
# table's normal at the program's A/B (TOOL_AXIS = -R [0 0 1], docs/experiment.md): with the
# head left vertical on the table at B-4 the compensated wall is 0.35 mm off.
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail=0
ok() { echo "ok   $1"; }
bad() { echo "FAIL $1"; fail=1; }

# Machining time of a 60 mm straight move from HOME at F<f> through an INI (hexcnc check):
# the feed's unit is what the time shows.
time_of() {
    printf 'G21 G90\nG1 X0 Y0 Z645 A0 B0 C0 F%s\nG1 Y60\nM2\n' "$2" > "$tmp/f.ngc"
    "$bin" check --json "$1" "$tmp/f.ngc" 2>&1 | sed -n 's/.*"machining_time_s":\([0-9.e+-]*\).*/\1/p'
}
within() { awk -v x="$1" -v lo="$2" -v hi="$3" 'BEGIN { exit !(x >= lo && x <= hi) }'; }
t=$(time_of "$root/configs/sim/tmu-hexapod.ini" 600)
within "$t" 5.9 6.2 && ok "configs/sim: F600 is 600 mm/min (60 mm in $t s)" ||
    bad "configs/sim: 60 mm at F600 take '$t' s, not 6 s"
for ini in "$root"/examples/paper/experiment/tmu-path*.ini; do
    t=$(time_of "$ini" 2)
    within "$t" 1.75 1.95 && ok "$(basename "$ini"): the paper's F2 is 2 m/min (60 mm in $t s)" ||
        bad "$(basename "$ini"): 60 mm at F2 take '$t' s, not 1.8 s"
done

# The INI and programs of `make run` (sim/module.mk).
run_ini=$(sed -n 's/^SIM_RUN_INI := *//p' "$root/sim/module.mk")
progs=$(awk '/^SIM_RUN_PROGRAMS :=/ { on = 1; sub(/^SIM_RUN_PROGRAMS :=/, "") }
             on { line = $0; sub(/\\$/, "", line); printf "%s ", line; if ($0 !~ /\\$/) on = 0 }' \
        "$root/sim/module.mk")
[ -n "$run_ini" ] && [ -f "$root/$run_ini" ] || { bad "make run's INI '$run_ini' not found"; exit 1; }
axis=$(sed -n 's/^TOOL_AXIS *= *//p' "$root/$run_ini")
for p in $progs; do
    ngc=$root/examples/paper/$p.ngc
    grep -q 'G14[12]' "$ngc" || continue
    for ab in $(sed 's/;.*//; s/([^)]*)//g' "$ngc" | grep -o 'A-*[0-9.]* B-*[0-9.]*' |
                tr ' ' ':' | sort -u); do
        a=${ab%%:*}; b=${ab##*:}
        if awk -v a="${a#A}" -v b="${b#B}" -v axis="$axis" 'BEGIN {
                split(axis, t, " "); r = 3.14159265358979 / 180
                # -R [0 0 1] with R = Ry(B) Rx(A): (-cos A sin B, sin A, -cos A cos B)
                e[1] = -cos(a * r) * sin(b * r); e[2] = sin(a * r); e[3] = -cos(a * r) * cos(b * r)
                n = sqrt(t[1] ^ 2 + t[2] ^ 2 + t[3] ^ 2)
                for (i = 1; i <= 3; i++) { d = t[i] / n - e[i]; if (d < -1e-6 || d > 1e-6) exit 1 }
            }'; then ok "make run: $p at $a $b on $run_ini: tool on the table normal"
        else bad "make run: $p at $a $b: TOOL_AXIS $axis of $run_ini is not -R [0 0 1]"; fi
    done
    "$bin" check "$root/$run_ini" "$ngc" > "$tmp/check.out" 2>&1 ||
        { bad "make run: $p does not check on $run_ini:"; cat "$tmp/check.out"; }
done
exit $fail
