#!/usr/bin/env bash
# Starts the workstation. Without a display (a server, CI) Qt has nothing to
# draw on: say so and run offscreen instead of failing.
set -u
cd "$(dirname "$0")/.."
if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ] && [ -z "${QT_QPA_PLATFORM:-}" ]; then
  echo "linpar: no display found (DISPLAY and WAYLAND_DISPLAY are unset); starting offscreen." >&2
  echo "linpar: set DISPLAY to see the window, or use the command line: .venv/bin/linpar --help" >&2
  export QT_QPA_PLATFORM=offscreen
  export LINPAR_EXIT_AFTER_S="${LINPAR_EXIT_AFTER_S:-3}"
fi
exec .venv/bin/linpar gui "$@"
