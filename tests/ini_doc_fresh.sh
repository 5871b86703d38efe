#!/bin/sh
# docs/ini.md is written from the key table (common/config_keys.c) by `make ini-doc`; this
# fails, showing the difference, when someone changed the table and not the page.
root=${HEXCNC_ROOT:-.}
bin=${HEXCNC_BIN:-$root/bin/hexcnc}
tmp=$(mktemp) || exit 1
trap 'rm -f "$tmp"' EXIT
"$bin" ini doc > "$tmp" || { echo "FAIL hexcnc ini doc failed"; exit 1; }
if ! diff -u "$root/docs/ini.md" "$tmp"; then
    echo "FAIL docs/ini.md is out of date: run 'make ini-doc' and commit it"
    exit 1
fi
echo "ok   docs/ini.md matches the key table ($(grep -c '^| `' "$tmp") keys)"
