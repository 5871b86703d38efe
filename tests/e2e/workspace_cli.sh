#!/bin/sh
# workspace_cli.sh: the workspace beyond the legs from the command line: `hexcnc check` names
# the joint-angle limit a program breaks (line, leg, amount); the mirror pose is refused by
# `hexcnc kins inverse` though its legs are as long as at HOME; `hexcnc kins workspace` reports
# the reach and its limits. Needs HEXCNC_ROOT and HEXCNC_BIN (make test sets them).
set -u
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
tmp=$(mktemp -d /tmp/hexcnc-workspace.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fails=0
check() {
    name=$1; shift
    if "$@"; then echo "ok   $name"; else echo "FAIL $name"; fails=$((fails + 1)); fi
}
has() { grep -q -- "$2" "$1"; }

cp "$root"/configs/sim/* "$tmp/"
ini=$tmp/tmu-hexapod.ini
sed -i 's/^SINGULAR_CONDITION = 50$/SINGULAR_CONDITION = 50\nBASE_JOINT_MAX_ANGLE = 40\nPLATFORM_JOINT_MAX_ANGLE = 45\nLEG_DIAMETER = 40\nLEG_CLEARANCE = 5/' "$ini"
check "the limits are in the test's INI" has "$ini" "PLATFORM_JOINT_MAX_ANGLE = 45"

printf 'G21 G90\nG0 X0 Y0 Z645\nG0 B10\nG0 B20\nM2\n' > "$tmp/tilt.ngc"
"$bin" check "$ini" "$tmp/tilt.ngc" > "$tmp/out" 2>&1
check "check refuses a tilt beyond the platform joints' angle (exit 1)" [ $? -eq 1 ]
check "... naming line 4, the leg, the angle, the excess and the key" has "$tmp/out" \
    "tilt.ngc:4: .*B20.000.*leg 1's platform joint would turn 49.41 deg from its axis, 4.41 deg beyond \[KINS\] PLATFORM_JOINT_MAX_ANGLE = 45 deg"
"$bin" check "$root/configs/sim/tmu-hexapod.ini" "$tmp/tilt.ngc" > "$tmp/out0" 2>&1
check "the same program on the machine without joint limits passes" [ $? -eq 0 ]

"$bin" kins "$root/configs/sim/tmu-hexapod.ini" inverse 0 0 -645 0 0 0 > "$tmp/mir" 2>&1
check "the mirror pose is refused (exit 1)" [ $? -eq 1 ]
check "... as the mirror assembly" has "$tmp/mir" "mirror assembly"

"$bin" kins "$ini" workspace 0 0 10 > "$tmp/ws" 2>&1
check "workspace exits 0" [ $? -eq 0 ]
check "workspace: +X limited by a base joint's angle" has "$tmp/ws" \
    "^+X .* mm   leg [0-9]'s base joint would turn 40.00 deg"
check "workspace: +Z limited by a leg's length" has "$tmp/ws" "^+Z .*(\[JOINT_[0-5]\]) would be 980"
check "workspace: twelve directions" [ "$(grep -c '^[+-][XYZABC] ' "$tmp/ws")" -eq 12 ]
"$bin" kins "$root/configs/sim/tmu-hexapod.ini" workspace > "$tmp/ws0" 2>&1
check "without the joint limits, +X reaches 439.86 mm (leg 2 at its maximum)" has "$tmp/ws0" \
    "^+X      439.86 mm   leg 2 (\[JOINT_1\]) would be 980"
# soft limits: [AXIS_Z] MAX_LIMIT, beside LinuxCNC's other [AXIS_Z] keys (ignored)
cp "$root/configs/sim/tmu-hexapod.ini" "$tmp/soft.ini"
printf '\n[AXIS_Z]\nMIN_LIMIT = 560\nMAX_LIMIT = 660\nMAX_VELOCITY = 30\n' >> "$tmp/soft.ini"
printf 'G21 G90\nG0 X0 Y0 Z650\nG1 Z670 F100\nM2\n' > "$tmp/high.ngc"
"$bin" check "$tmp/soft.ini" "$tmp/high.ngc" > "$tmp/out" 2>&1
check "check refuses a move above [AXIS_Z] MAX_LIMIT (exit 1)" [ $? -eq 1 ]
check "... naming line 3, the amount and the key" has "$tmp/out" \
    "high.ngc:3: .*Z670.000 is 10.000 mm above \[AXIS_Z\] MAX_LIMIT = 660"
printf 'MAX_LIMITS = 660\n' >> "$tmp/soft.ini"
"$bin" check "$tmp/soft.ini" "$tmp/high.ngc" > "$tmp/out" 2>&1
check "a misspelt soft limit is an error naming it" has "$tmp/out" 'AXIS_Z\] MAX_LIMITS: unknown key'
# leg clearance: legs 95 mm thick kept 5 mm apart; turning A passes legs 3 and 4 closer
cp "$root/configs/sim/tmu-hexapod.ini" "$tmp/legs.ini"
sed -i 's/^SINGULAR_CONDITION = 50$/SINGULAR_CONDITION = 50\nLEG_DIAMETER = 95\nLEG_CLEARANCE = 5/' "$tmp/legs.ini"
printf 'G21 G90\nG0 X0 Y0 Z645\nG1 A30 F600\nG1 A45\nM2\n' > "$tmp/roll.ngc"
"$bin" check "$tmp/legs.ini" "$tmp/roll.ngc" > "$tmp/out" 2>&1
check "check refuses a roll that brings two legs closer than LEG_DIAMETER + LEG_CLEARANCE" \
    [ $? -eq 1 ]
check "... naming line 4, the legs, the distance and the keys" has "$tmp/out" \
    "roll.ngc:4: .*legs 3 and 4 would pass .* mm apart (axis to axis), .* mm closer than \[KINS\] LEG_DIAMETER 95 mm + LEG_CLEARANCE 5 mm"
"$bin" kins "$tmp/legs.ini" workspace > "$tmp/ws" 2>&1
check "workspace: +A limited by legs 3 and 4's clearance at 43.19 deg" has "$tmp/ws" \
    "^+A       43.19 deg  legs 3 and 4 would pass 100.00 mm apart"
echo "workspace_cli: $fails failed"
[ "$fails" -eq 0 ]
