#!/bin/sh
# A misspelt key in a machine's INI stops `hexcnc run`, `check`, `kins`, `interp -i` and
# `halcmd -i` before anything starts, naming file, line and the closest known key; a missing
# leg limit is named too. Before, MAX_VELOCTY = 20 silently left the leg at 100 mm/s.
# `hexcnc ini check` finds the same, and what only keys together say (the jerk limits).
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
pass=0; fail=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; fail=$((fail + 1)); }
# A copy of the simulated machine beside its HAL files, with one leg's limit misspelt.
cfg=$root/configs/sim
cp "$cfg"/*.hal "$cfg"/*.tbl "$tmp"/
sed -e "s#^OPEN_FILE = \.\./\.\./#OPEN_FILE = $root/#" "$cfg/tmu-hexapod.ini" > "$tmp/good.ini"
awk '/^\[JOINT_3\]/ { j = 1 } j && /^MAX_VELOCITY/ { print "MAX_VELOCTY = 20"; j = 0; next }
     { print }' "$tmp/good.ini" > "$tmp/typo.ini"
line=$(grep -n '^MAX_VELOCTY' "$tmp/typo.ini" | cut -d: -f1)
want="$tmp/typo.ini:$line: [JOINT_3] MAX_VELOCTY: unknown key; did you mean MAX_VELOCITY?"
prog=$root/tests/check/straight_cut.ngc
for cmd in "run --quiet $tmp/typo.ini $prog" "check $tmp/typo.ini $prog" \
           "kins $tmp/typo.ini inverse 0 0 645 0 0 0" "interp -i $tmp/typo.ini $prog" \
           "halcmd -i $tmp/typo.ini show pin"; do
    name=${cmd%% *}
    # shellcheck disable=SC2086
    timeout 60 "$bin" $cmd > "$tmp/out" 2>&1
    st=$?
    if [ $st -ne 0 ] && [ $st -ne 124 ]; then ok "$name exits $st"; else bad "$name exits $st"; fi
    if grep -qF "$want" "$tmp/out"; then ok "$name names file, line and MAX_VELOCITY"
    else bad "$name: no '$want' in:"; cat "$tmp/out"; fi
    if grep -q "progress\|machining time\|finished" "$tmp/out"; then bad "$name started"; fi
done
# The same file with the misspelt line gone: the leg has no speed limit, which is an error.
grep -v '^MAX_VELOCTY' "$tmp/typo.ini" > "$tmp/missing.ini"
"$bin" check "$tmp/missing.ini" "$prog" > "$tmp/out" 2>&1 && bad "missing limit accepted"
if grep -qF "[JOINT_3] MAX_VELOCITY: missing; it has no default" "$tmp/out" &&
   grep -qF "$tmp/missing.ini:" "$tmp/out"; then ok "missing MAX_VELOCITY named with the file"
else bad "missing MAX_VELOCITY:"; cat "$tmp/out"; fi
# The good file still runs.
if "$bin" check "$tmp/good.ini" "$prog" > "$tmp/out" 2>&1; then ok "the good copy checks"
else bad "the good copy:"; cat "$tmp/out"; fi
# `hexcnc ini check`: quiet and 0 on the good copy; the misspelt key named with its line;
# and what only keys together say, found by building the machine as `hexcnc check` does:
# jerk limits on the path but not on the legs, and a JERK_WINDOW longer than they need.
if "$bin" ini check "$tmp/good.ini" > "$tmp/out" 2>&1 && [ ! -s "$tmp/out" ]; then
    ok "ini check passes the good copy, quietly"
else bad "ini check on the good copy:"; cat "$tmp/out"; fi
"$bin" ini check "$tmp/typo.ini" > "$tmp/out" 2>&1 && bad "ini check passed the typo"
if grep -qF "$want" "$tmp/out"; then ok "ini check names file, line and MAX_VELOCITY"
else bad "ini check on the typo:"; cat "$tmp/out"; fi
sed 's/^MAX_ANGULAR_ACCELERATION.*/&\nMAX_LINEAR_JERK = 50000\nMAX_ANGULAR_JERK = 30000/' \
    "$tmp/good.ini" > "$tmp/jerk_path.ini"
"$bin" ini check "$tmp/jerk_path.ini" > "$tmp/out" 2>&1 && bad "ini check passed half the jerk limits"
line=$(awk '/^\[JOINT_0\]/ { j = 1; next } j && /^[A-Z]/ { print NR; exit }' "$tmp/jerk_path.ini")
if grep -qF "$tmp/jerk_path.ini:$line: [JOINT_0] MAX_JERK: missing; jerk limits are all set" \
   "$tmp/out"
then ok "ini check: jerk limits on the path only, the legs' missing one named at [JOINT_0]"
else bad "ini check on half the jerk limits:"; cat "$tmp/out"; fi
sed 's/^MAX_ACCELERATION.*/&\nMAX_JERK = 50000/; s/^MAX_LINEAR_JERK.*/&\nJERK_WINDOW = 0.05/' \
    "$tmp/jerk_path.ini" > "$tmp/window.ini"
line=$(grep -n '^JERK_WINDOW' "$tmp/window.ini" | cut -d: -f1)
"$bin" ini check "$tmp/window.ini" > "$tmp/out" 2>&1 && bad "ini check passed a long window"
if grep -qF "$tmp/window.ini:$line: [TRAJ] JERK_WINDOW = 0.05 s: longer than the 0.0400 s" \
   "$tmp/out"; then ok "ini check: JERK_WINDOW longer than the jerk limits need, with its line"
else bad "ini check on a long window:"; cat "$tmp/out"; fi
sed 's/^JERK_WINDOW = 0.05$/JERK_WINDOW = 0.02/' "$tmp/window.ini" > "$tmp/window2.ini"
if "$bin" ini check "$tmp/window2.ini" > "$tmp/out" 2>&1 && [ ! -s "$tmp/out" ]; then
    ok "ini check passes a 20 ms window"
else bad "ini check on a 20 ms window:"; cat "$tmp/out"; fi
[ $fail -eq 0 ] && echo "ini_check_cli: $pass passed" && exit 0
echo "ini_check_cli: $fail failed"; exit 1
