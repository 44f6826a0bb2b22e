#!/usr/bin/env bash
# bench/realtime_picture.sh [OPTIONS]: the README's picture of the real-time methods
# (docs/images/realtime_methods.png); installs python3-pil, then runs bench/realtime_picture.py
# (its docstring lists the options). Not a test.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
source "$repo/scripts/apt_packages.sh"
apt_install_missing "realtime_picture" python3-pil
[ -x "$repo/build/narval" ] || "$repo/scripts/setup.sh"
exec /usr/bin/python3 "$repo/bench/realtime_picture.py" "$@"
