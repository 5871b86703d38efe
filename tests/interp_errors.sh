#!/bin/sh
# Runs `hexcnc interp` on every malformed program in tests/interp_errors/ and checks that it
# fails with exactly the error line stored beside it in NAME.err ("file:line:col: error: ...").
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
dir=$root/tests/interp_errors
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
pass=0; fail=0
for ngc in "$dir"/*.ngc; do
    name=$(basename "$ngc" .ngc)
    if (cd "$dir" && "$bin" interp "$name.ngc") > "$tmp/out" 2> "$tmp/err"; then
        echo "FAIL $name: the program was accepted"
        fail=$((fail + 1))
        continue
    fi
    expected=$(cat "$dir/$name.err")
    got=$(tail -n 1 "$tmp/err")
    if [ "$got" != "$expected" ]; then
        echo "FAIL $name:"
        echo "  expected: $expected"
        echo "  got:      $got"
        fail=$((fail + 1))
        continue
    fi
    echo "ok   $name"
    pass=$((pass + 1))
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
