#!/usr/bin/env bash
# Install headless Chromium for the documentation's browser check (scripts/docs_browser_check.py)
# where none is installed: Debian's package, as root or through sudo. Nothing to do where a
# Chromium is already on PATH.
set -euo pipefail
for name in chromium chromium-browser google-chrome; do
  command -v "$name" >/dev/null 2>&1 && exit 0
done
if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi
if ! command -v apt-get >/dev/null 2>&1; then
  echo "setup-browser: no Chromium and no apt-get: install Chromium by hand (the docs check needs it)" >&2
  exit 2
fi
echo "setup-browser: installing Debian's chromium for the docs browser check"
$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends chromium >/dev/null \
  || { $SUDO apt-get update -q >/dev/null && \
       $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends chromium >/dev/null; }
command -v chromium >/dev/null
