#!/bin/sh
# cli_help.sh: every subcommand of bin/hexcnc (as `hexcnc --help` lists them) and
# scripts/hexcnc-start answer -h and --help with their usage on stdout and exit 0; `hexcnc
# run --quiet` prints only the summary; progress lines come at every further 10 % of a program
# (simulated clock, so the figures do not depend on how busy the machine is).
# Needs HEXCNC_ROOT and HEXCNC_BIN (make test sets them).
set -u
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
start="$root/scripts/hexcnc-start"
ini="$root/configs/sim/tmu-hexapod.ini"
prog="$root/examples/paper/prog10_g141_d20.ngc"
tmp=$(mktemp -d /tmp/hexcnc-cli-help.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
export HEXCNC_BIN="$bin"
fails=0

check() {
    name=$1; shift
    if "$@"; then echo "ok   $name"; else echo "FAIL $name"; fails=$((fails + 1)); fi
}
has() { grep -q -- "$2" "$1"; }
hasnt() { ! grep -q -- "$2" "$1"; }
empty() { [ ! -s "$1" ]; }

# 1. The top level.
"$bin" --help >"$tmp/top" 2>"$tmp/err"
check "hexcnc --help exits 0" [ $? -eq 0 ]
check "hexcnc --help: usage on stdout" has "$tmp/top" "usage: hexcnc COMMAND"
cmds=$(sed -n 's/^  \([a-z_][a-z_]*\).*/\1/p' "$tmp/top")
check "hexcnc --help lists the subcommands" [ "$(echo "$cmds" | wc -w)" -ge 7 ]

# 2. Every subcommand, with -h and --help, alone and after other arguments.
for c in $cmds; do
    for h in -h --help; do
        for pre in "" "$ini"; do
            "$bin" "$c" $pre "$h" >"$tmp/out" 2>"$tmp/err"
            rc=$?
            check "hexcnc $c ${pre:+INI }$h exits 0" [ $rc -eq 0 ]
            check "hexcnc $c ${pre:+INI }$h: usage on stdout" has "$tmp/out" "^usage: hexcnc $c"
            check "hexcnc $c ${pre:+INI }$h: nothing on stderr" empty "$tmp/err"
        done
    done
done

# 3. scripts/hexcnc-start.
for h in -h --help; do
    sh "$start" "$h" >"$tmp/out" 2>"$tmp/err"
    check "hexcnc-start $h exits 0" [ $? -eq 0 ]
    check "hexcnc-start $h: usage on stdout" has "$tmp/out" "^usage: hexcnc-start"
done

# 4. --quiet: the summary and nothing else (progress, plan, banner all gone).
"$bin" run --quiet --sim-clock "$ini" "$prog" >"$tmp/out" 2>"$tmp/err"
check "run --quiet exits 0" [ $? -eq 0 ]
check "run --quiet: summary first" [ "$(head -n 1 "$tmp/out")" = "summary of $prog:" ]
check "run --quiet: no progress" hasnt "$tmp/out" "^  line "
check "run --quiet: no plan" hasnt "$tmp/out" "^planned:"
check "run --quiet: no banner" hasnt "$tmp/out" "^hexcnc run: machine"
check "run --quiet: no closing line" hasnt "$tmp/out" "program finished"
sh "$start" --quiet --sim-clock "$ini" "$prog" >"$tmp/out" 2>"$tmp/err"
check "hexcnc-start --quiet: summary first" [ "$(head -n 1 "$tmp/out")" = "summary of $prog:" ]

# 5. Progress (not a terminal): a line in every tenth of the program, then 100 %. The
# program takes 4.96 s of machine time, less than [TASK] PROGRESS_INTERVAL (5 s): only the
# 10 % rule can produce these lines.
"$bin" run --sim-clock "$ini" "$prog" >"$tmp/out" 2>"$tmp/err"
sed -n 's/^  line [0-9]*: \([0-9.]*\) %.*/\1/p' "$tmp/out" >"$tmp/pct"
for k in 0 1 2 3 4 5 6 7 8 9; do
    check "progress line between $((k * 10)) and $((k * 10 + 10)) %" \
        awk -v lo=$((k * 10)) '$1 >= lo && $1 < lo + 10 { f = 1 } END { exit !f }' "$tmp/pct"
done
check "progress ends at 100 %" [ "$(tail -n 1 "$tmp/pct")" = "100.0" ]

[ $fails -eq 0 ] && echo "cli_help: all passed"
[ $fails -eq 0 ]
