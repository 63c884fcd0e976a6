#!/usr/bin/env bash
# System libraries the Python packages need but pip cannot install:
# open3d's wheel links libusb-1.0 and fails to import without it.
set -euo pipefail
if ldconfig -p 2>/dev/null | grep -q 'libusb-1.0.so.0'; then
  exit 0
fi
echo "installing libusb-1.0 (needed by open3d) with apt-get" >&2
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq libusb-1.0-0 >/dev/null
