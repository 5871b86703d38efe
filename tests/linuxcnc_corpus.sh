#!/bin/sh
# linuxcnc_corpus.sh: every G-code program LinuxCNC ships (Debian linuxcnc-uspace:
# /usr/share/linuxcnc/ncfiles and /usr/share/doc/linuxcnc/examples; lathe programs aside) run
# through LinuxCNC's `rs274 -g` and `hexcnc interp`, each in the program's folder. Of the
# programs rs274 accepts, it counts those hexcnc accepts and those whose motion lines
# (STRAIGHT_TRAVERSE, STRAIGHT_FEED, STRAIGHT_PROBE, ARC_FEED, DWELL, RIGID_TAP, the spindle
# synchronisation around G33, with the N column) are identical, and
# lists hexcnc's refusals grouped by their message. It fails when either count falls below
# the figures recorded here (raise them as the interpreter learns more); it prints SKIP
# where rs274 or the programs are not installed.
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
MIN_ACCEPTED=169     # of the programs rs274 accepts (measured: 169 of 169)
MIN_IDENTICAL=168    # of those, motion identical to rs274's (measured: 168)
if ! command -v rs274 > /dev/null 2>&1 || [ ! -d /usr/share/linuxcnc/ncfiles ] ||
   [ ! -f /usr/share/doc/linuxcnc/examples/sample-configs/sim/sim.tbl ]; then
    echo "SKIP linuxcnc_corpus: rs274 or LinuxCNC's programs are not installed (linuxcnc-uspace)"
    exit 0
fi
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
# Both run with LinuxCNC's sim tool table, as a machinist runs programs with the machine's
# table: rs274 alone reads a table in inches (its machine units), hexcnc in mm, so hexcnc
# gets the same tools with every length (X Y Z U V W D) in mm as rs274 has them: divided by
# rs274's own factor, 0.03937007874016 in/mm (not 1/25.4 exactly: a tool of D0.201 is
# 5.1054 mm less 1.6e-13 to rs274, which moves a compensated arc's last digit)
tbl=/usr/share/doc/linuxcnc/examples/sample-configs/sim/sim.tbl
awk '{ out = ""
       for (i = 1; i <= NF; i++) {
           t = $i
           if (t ~ /^;/) { for (j = i; j <= NF; j++) out = out " " $j; break }
           c = substr(t, 1, 1)
           if (c ~ /[XYZUVWDxyzuvwd]/)
               t = sprintf("%s%.17g", c, substr(t, 2) / 0.03937007874016)
           out = out " " t
       }
       print substr(out, 2) }' "$tbl" > "$tmp/tools_mm.tbl"
# rs274 keeps its tool data in $HOME/.tool.mmap, truncated by every run: each run here gets
# a HOME of its own, so that other rs274 runs on the machine cannot pull it from under it
mkdir "$tmp/home"
# A zero rs274 prints with a minus sign (-0.0000: a value of about -1e-16 after a rounding
# that differs in the last bit) is the zero it is.
motion() { grep -E 'STRAIGHT_TRAVERSE|STRAIGHT_FEED|STRAIGHT_PROBE|ARC_FEED|DWELL|RIGID_TAP|SPEED_FEED_SYNC' | cut -c7- |
           sed -E 's/-(0\.0+)([,)])/\1\2/g'; }
find /usr/share/linuxcnc/ncfiles /usr/share/doc/linuxcnc/examples -name '*.ngc' |
    grep -vi lathe | sort > "$tmp/list"
total=0; reference=0; accepted=0; identical=0
: > "$tmp/refused"
while IFS= read -r f; do
    total=$((total + 1))
    d=$(dirname "$f"); b=$(basename "$f")
    (cd "$d" && HOME="$tmp/home" timeout 20 rs274 -t "$tbl" -g "$b" < /dev/null \
        > "$tmp/rs.out" 2> /dev/null) || continue
    reference=$((reference + 1))
    if ! (cd "$d" && timeout 20 "$bin" interp -t "$tmp/tools_mm.tbl" "$b" < /dev/null > "$tmp/hx.out" 2> "$tmp/hx.err")
    then
        msg=$(head -1 "$tmp/hx.err" | sed -E 's/^[^:]*:[0-9]+(:[0-9]+)?: (error: )?//' | cut -c1-90)
        printf '%s\t%s\n' "$msg" "$f" >> "$tmp/refused"
        continue
    fi
    accepted=$((accepted + 1))
    motion < "$tmp/rs.out" > "$tmp/rs.m"
    motion < "$tmp/hx.out" > "$tmp/hx.m"
    if cmp -s "$tmp/rs.m" "$tmp/hx.m"; then
        identical=$((identical + 1))
    else
        echo "differs from rs274: $f (first difference: $(diff "$tmp/rs.m" "$tmp/hx.m" | sed -n 2p))"
    fi
done < "$tmp/list"
echo "refused by hexcnc, by message (count, message):"
cut -f1 "$tmp/refused" | sort | uniq -c | sort -rn
echo "linuxcnc_corpus: $total programs, $reference accepted by rs274; hexcnc accepts $accepted" \
     "of those, $identical with identical motion"
fails=0
[ "$accepted" -ge "$MIN_ACCEPTED" ] || { echo "FAIL accepted $accepted < $MIN_ACCEPTED"; fails=1; }
[ "$identical" -ge "$MIN_IDENTICAL" ] || { echo "FAIL identical $identical < $MIN_IDENTICAL"; fails=1; }
[ "$fails" -eq 0 ]
