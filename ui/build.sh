#!/bin/sh
# build.sh OUT: builds the operator's page into OUT (index.html, app.js, style.css).
# The libraries come from npm as package-lock.json pins them (three.js; esbuild bundles),
# installed into ui/node_modules once; the page loads nothing from elsewhere at run time.
set -eu
mkdir -p "$1"
out=$(cd "$1" && pwd)
cd "$(dirname "$0")"
if [ ! -f node_modules/.package-lock.json ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
    npm ci --no-audit --no-fund --loglevel=error
fi
node_modules/.bin/esbuild src/main.js --bundle --minify --sourcemap --target=es2020 \
    --log-level=warning --outfile="$out/app.js"
cp src/index.html src/style.css "$out/"
