#!/bin/sh
# paper_programs.sh: runs examples/paper/*.ngc through `hexcnc interp` (FEED_UNITS = m/min, the
# simulated machine's tool table) and compares the compensated moves with the paper's worked
# numbers (docs/compensation.md), to 1e-6 mm. Run by `make test` (HEXCNC_BIN, HEXCNC_ROOT set).
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
printf '[RS274NGC]\nFEED_UNITS = m/min\n' > "$tmp/paper.ini"
fail=0

# check FILE "X Y Z" ... : the program's STRAIGHT_FEED targets, in order, must be these points.
check() {
    f=$1; shift
    if ! "$bin" interp -i "$tmp/paper.ini" -t "$root/configs/sim/tmu-hexapod.tbl" --digits 6 \
         "$root/examples/paper/$f" > "$tmp/out" 2> "$tmp/err"; then
        echo "FAIL $f: interp failed: $(cat "$tmp/err")"; fail=1; return
    fi
    sed -n 's/.*STRAIGHT_FEED(\([^,]*\), *\([^,]*\), *\([^,]*\),.*/\1 \2 \3/p' "$tmp/out" > "$tmp/got"
    for p in "$@"; do echo "$p"; done > "$tmp/want"
    if ! awk 'NR == FNR { w[FNR] = $0; n = FNR; next }
              { split(w[FNR], e, " "); m = FNR
                for (i = 1; i <= 3; i++) { d = $i - e[i]; if (d < 0) d = -d; if (d > 1.5e-6) bad = 1 } }
              END { exit (bad || m != n) }' "$tmp/want" "$tmp/got"; then
        echo "FAIL $f: moves"; cat "$tmp/got"; echo "expected"; cat "$tmp/want"; fail=1; return
    fi
    grep -q "SET_FEED_RATE(2" "$tmp/out" || { echo "FAIL $f: feed is not F2 (m/min)"; fail=1; return; }
    echo "ok   $f"
}

check prog10_g141_d20.ngc "59.975641 -80 630.697565" "59.975641 -20 630.697565"
check prog11_g141_d10.ngc "54.987820 -30 630.348782" "54.987820 20 630.348782"
check prog10_g142_d20.ngc "40.024359 -80 629.302435" "40.024359 -20 629.302435"
check prog11_g142_d10.ngc "45.012180 -30 629.651218" "45.012180 20 629.651218"
check path2_g141_d20.ngc "39.902681 -100 659.391731" "39.902681 50 659.391731"
check path2_g141_d12.ngc "35.941608 -100 658.835039" "35.941608 50 658.835039"
check path1_tooltable.ngc "59.975641 -80 630.697565" "59.975641 -20 630.697565" \
                          "54.987820 -30 630.348782" "54.987820 20 630.348782"
exit $fail
