#!/usr/bin/env bash
# Install Debian's Chromium for the studio's browser tests (tests/test_studio_browser.py).
#
# Playwright (a dev dependency from PyPI) drives it with executable_path=/usr/bin/chromium;
# Playwright's own browser download is not used. Without Chromium those tests are skipped
# with a reason.
#
# Then axe-core (npm, pinned in tests/browser-deps/package-lock.json), which the browser
# tests inject into the page for their accessibility checks: `npm ci` there when npm
# exists. Without it those checks are skipped with a reason (failed where
# NAVSEQ_EXPECT_BROWSER=1, as .ci/run sets when Chromium is there).
set -euo pipefail
cd "$(dirname "$0")/.."
install_chromium() {
  if [ -x /usr/bin/chromium ]; then
    return 0
  fi
  if ! command -v apt-get >/dev/null; then
    echo "install-browser: no apt-get; install Chromium yourself (or set NAVSEQ_CHROMIUM)" >&2
    return 0
  fi
  local sudo=""
  if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends chromium
}
install_chromium
if command -v npm >/dev/null; then
  (cd tests/browser-deps && npm ci --no-audit --no-fund --loglevel=error)
else
  echo "install-browser: no npm; the studio's accessibility checks (axe-core) will be skipped" >&2
fi
