#!/bin/sh
# comp5_gouge_cli.sh: a G142 pocket started at a corner gouges 5 mm into its closing wall;
# `hexcnc interp`, `hexcnc check` and `hexcnc run` must all refuse it with file:line, depth and
# point (run: before any motion), and accept the same pocket started mid-edge.
# Run by `make test` (HEXCNC_BIN, HEXCNC_ROOT, HEXCNC_PLUGIN_DIR set).
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
ini=$root/configs/sim/tmu-hexapod.ini
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
fail=0
want='corner.ngc:3: error: G142 at line 3 gouges the contour from line 6 to 7 by 5.0000 mm at X-10.0000 Y-5.0000 Z630.0000 (tool radius 5 mm)'
# The 40 x 30 pocket X-10..30 Y-10..20 at Z630, counter-clockwise, started at its corner ...
cat > "$tmp/corner.ngc" <<'NGC'
G21 G90
G0 X10 Y5 Z630 A0 B0 C0
G142 X-10 Y-10 Z630 W5 F500
G142 X30 Y-10
G142 X30 Y20
G142 X-10 Y20
G142 X-10 Y-10
G0 X10 Y5
M2
NGC
# ... and in the middle of its first edge
cat > "$tmp/midedge.ngc" <<'NGC'
G21 G90
G0 X10 Y5 Z630 A0 B0 C0
G142 X10 Y-10 Z630 W5 F500
G142 X30 Y-10
G142 X30 Y20
G142 X-10 Y20
G142 X-10 Y-10
G142 X10 Y-10
G0 X10 Y5
M2
NGC
cd "$tmp" || exit 1
refused() { # refused NAME COMMAND...: fails, and says $want
    name=$1; shift
    if "$@" > out 2> err; then echo "FAIL $name: accepted"; fail=1; return; fi
    if ! grep -qF "$want" out err; then echo "FAIL $name:"; cat out err; fail=1; return; fi
    echo "ok   $name refuses the corner start"
}
refused interp "$bin" interp corner.ngc
refused check "$bin" check "$ini" corner.ngc
refused run "$bin" run --sim-clock --quiet "$ini" corner.ngc
if ! grep -q "not started; the machine did not move" err; then
    echo "FAIL run: moved or did not say so"; cat err; fail=1
fi
for c in interp check; do
    if [ "$c" = interp ]; then "$bin" interp midedge.ngc > out 2> err; else
        "$bin" check "$ini" midedge.ngc > out 2> err; fi
    if [ $? -ne 0 ]; then echo "FAIL $c: mid-edge start refused"; cat out err; fail=1
    else echo "ok   $c accepts the mid-edge start"; fi
done
exit $fail
