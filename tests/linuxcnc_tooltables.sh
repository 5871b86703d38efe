#!/bin/sh
# Loads every tool table LinuxCNC ships (Debian linuxcnc-uspace) with `hexcnc interp -t`, and
# on a copy of each sets one tool's radius with G10 L1, run on the simulated machine (settings
# are saved when their line executes, so only `hexcnc run` writes): the saved file must differ
# from the original in exactly that one line (comments, blank lines, order and number formats
# kept), and `hexcnc interp` of the same program must leave the copy as it was.
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
ex=${LINUXCNC_EXAMPLES:-/usr/share/doc/linuxcnc/examples}
if [ ! -d "$ex" ]; then
    echo "SKIP linuxcnc_tooltables: $ex does not exist (install linuxcnc-uspace)"
    exit 0
fi
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
printf 'M2\n' > "$tmp/empty.ngc"
# The simulated machine with its tool table replaced by the copy under test.
ini="$root/examples/paper/experiment/tmu-path1.ini"
sed -e "s|^HALFILE = \.\./\.\./\.\./|HALFILE = $root/|" \
    -e "s|^TOOL_TABLE = .*|TOOL_TABLE = $tmp/copy.tbl|" "$ini" > "$tmp/machine.ini"
loaded=0; refused=0; dangling=0; rewritten=0; bad=0
find "$ex" -name '*.tbl' | sort > "$tmp/list"
while IFS= read -r tbl; do
    if [ ! -e "$tbl" ]; then              # a symbolic link to a file not shipped
        echo "skip $tbl: dangling symbolic link"
        dangling=$((dangling + 1))
        continue
    fi
    if ! "$bin" interp -t "$tbl" "$tmp/empty.ngc" > /dev/null 2> "$tmp/err"; then
        echo "REFUSED $tbl: $(cat "$tmp/err")"
        refused=$((refused + 1))
        continue
    fi
    loaded=$((loaded + 1))
    # The first ordinary tool (1..9999) of the table gets a new radius.
    t=$(sed -n 's/^[[:space:]]*[Tt]\([0-9][0-9]*\).*/\1/p; s/^[[:space:]]*\([0-9][0-9]*\)[[:space:]].*/\1/p' "$tbl" |
        awk '$1 >= 1 && $1 < 10000 { print; exit }')
    [ -n "$t" ] || continue
    cp "$tbl" "$tmp/copy.tbl"
    printf 'G21 G10 L1 P%s R1.2345\nM2\n' "$t" > "$tmp/g10.ngc"
    "$bin" interp -t "$tmp/copy.tbl" "$tmp/g10.ngc" > /dev/null 2> "$tmp/err"
    if ! cmp -s "$tbl" "$tmp/copy.tbl"; then
        echo "FAIL $tbl: hexcnc interp of a G10 L1 program changed the table"
        bad=$((bad + 1))
        continue
    fi
    if ! "$bin" run --quiet "$tmp/machine.ini" "$tmp/g10.ngc" > /dev/null 2> "$tmp/err"; then
        echo "FAIL $tbl: G10 L1 P$t: $(cat "$tmp/err")"
        bad=$((bad + 1))
        continue
    fi
    changed=$(diff "$tbl" "$tmp/copy.tbl" | grep -c '^[<>]')
    if [ "$changed" -ne 2 ] || ! diff "$tbl" "$tmp/copy.tbl" | grep -q '^>.*2\.469'; then
        echo "FAIL $tbl: G10 L1 P$t changed more or other than tool $t's line:"
        diff "$tbl" "$tmp/copy.tbl" | head -10
        bad=$((bad + 1))
        continue
    fi
    rewritten=$((rewritten + 1))
done < "$tmp/list"
echo "linuxcnc_tooltables: $loaded loaded, $refused refused, $dangling dangling links skipped;" \
     "$rewritten rewritten by G10 L1 with one line changed, $bad failed"
[ "$refused" -eq 0 ] && [ "$bad" -eq 0 ] && [ "$loaded" -gt 0 ]
