#!/usr/bin/env bash
# Runs the browser end-to-end test: installs playwright-core from npm into
# tests/browser/node_modules when missing (package.json pins the range), then
# drives Debian's Chromium (/usr/bin/chromium, package "chromium").
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
command -v node >/dev/null || { echo "browser test: node is not installed (Debian package nodejs)" >&2; exit 1; }
[ -x "${SIGHTLINE_CHROMIUM:-/usr/bin/chromium}" ] || { echo "browser test: /usr/bin/chromium is missing (Debian package chromium)" >&2; exit 1; }
if [ ! -d "$here/node_modules/playwright-core" ]; then
  (cd "$here" && npm install --no-audit --no-fund --no-package-lock --loglevel=error)
fi
exec node "$here/test_browser.cjs"
