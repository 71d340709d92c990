#!/usr/bin/env bash
# The headless browser of the browser tests (tests/reports/test_webreport_browser.py): Chromium and its
# WebDriver, from the system's packages. Quick when they are there; when they cannot be installed
# (no apt-get, no root, no network) it says why and exits 0, and those tests skip with that reason.
set -u

have() { command -v "$1" >/dev/null 2>&1; }
browser() { have chromium || have chromium-browser || have google-chrome; }

if browser && have chromedriver; then
    exit 0
fi
if ! have apt-get; then
    echo "setup_browser: no apt-get here; install Chromium and chromedriver to run the browser tests" >&2
    exit 0
fi
if [ "$(id -u)" -eq 0 ]; then
    SUDO=""
elif have sudo && sudo -n true 2>/dev/null; then
    SUDO="sudo -n"
else
    echo "setup_browser: apt-get needs root; run: sudo apt-get install -y chromium chromium-driver" >&2
    exit 0
fi
echo "setup_browser: installing chromium and chromium-driver (apt-get)" >&2
if ! { $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
        $SUDO apt-get install -y -qq --no-install-recommends chromium chromium-driver; } >&2; then
    echo "setup_browser: apt-get could not install chromium; the browser tests will skip" >&2
fi
exit 0
