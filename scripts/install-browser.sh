#!/usr/bin/env bash
# Install Debian's Chromium for the studio's browser tests (tests/test_studio_browser.py).
#
# Playwright (a dev dependency from PyPI) drives it with executable_path=/usr/bin/chromium;
# Playwright's own browser download is not used. Without Chromium those tests are skipped
# with a reason.
set -euo pipefail
if [ -x /usr/bin/chromium ]; then
  exit 0
fi
if ! command -v apt-get >/dev/null; then
  echo "install-browser: no apt-get; install Chromium yourself (or set NAVSEQ_CHROMIUM)" >&2
  exit 0
fi
sudo=""
if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends chromium
