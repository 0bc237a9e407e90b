#!/usr/bin/env bash
# Installs the browser tests' npm packages (puppeteer-core, pinned in tests/js/package-lock.json)
# with `npm ci` when they are missing or older than the lock file; otherwise does nothing.
# scripts/setup.sh runs it, and so does the ctest fixture browser.npm_ci before the browser tests
# (tests/web, tests/report), so a work tree configured by hand installs them once too.
set -euo pipefail
dir="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [ ! -f "$dir/node_modules/.package-lock.json" ] || [ ! -f "$dir/node_modules/puppeteer-core/package.json" ] || \
   [ "$dir/package-lock.json" -nt "$dir/node_modules/.package-lock.json" ]; then
  echo "tests/js: installing puppeteer-core with npm ci" >&2
  npm ci --prefix "$dir" --no-audit --no-fund --loglevel=error >/dev/null
fi
echo "tests/js: puppeteer-core $(node -p "require('$dir/node_modules/puppeteer-core/package.json').version") installed"
