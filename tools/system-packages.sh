#!/usr/bin/env bash
# Installs the Debian packages linpar needs (PortAudio for the sound card,
# jackd2 for the virtual rig, the libraries Qt loads, poppler-utils' pdftoppm for
# the report tests, postgresql for the PostgreSQL archive's tests: a throw-away
# server is started from its binaries, the package's own cluster is not used, xvfb for the
# test that opens the real window), when they are missing.
# Qt's xcb platform plugin (libqxcb.so, libQt6XcbQpa.so.6) loads every libxcb-* below:
# without libxcb-icccm4 and libxcb-keysyms1 a desktop gets "Could not load the Qt platform
# plugin 'xcb'" and no window. Check with ldd on both: no line may say "not found".
# fonts-droid-fallback (1.8 MB; fonts-noto-cjk would be 57 MB) draws the Chinese and Japanese characters of a
# driver's name that the PDF report's DejaVu Sans lacks (analysis/report/fonts.py); without it they are written as
# a stand-in. matplotlib lists the fonts once: on a machine that ran linpar before, delete
# ~/.cache/matplotlib/fontlist-*.json after installing it.
# As root it installs them with apt-get; otherwise it says what to install.
set -u
needed=(libportaudio2 jackd2 libegl1 libgl1 libxkbcommon0 libxkbcommon-x11-0 libfontconfig1 libdbus-1-3 libglib2.0-0
        libx11-6 libx11-xcb1 libxcb1 libxcb-cursor0 libxcb-glx0 libxcb-icccm4 libxcb-image0 libxcb-keysyms1
        libxcb-randr0 libxcb-render0 libxcb-render-util0 libxcb-shape0 libxcb-shm0 libxcb-sync1 libxcb-util1
        libxcb-xfixes0 libxcb-xkb1
        poppler-utils postgresql xvfb x11-utils fonts-droid-fallback)
missing=()
for pkg in "${needed[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
[ ${#missing[@]} -eq 0 ] && exit 0
if [ "$(id -u)" -ne 0 ]; then
  echo "linpar needs these Debian packages: ${missing[*]}" >&2
  echo "Install them with: sudo apt-get install ${missing[*]}" >&2
  echo "(continuing: the in-process simulator works without PortAudio and JACK)" >&2
  exit 0
fi
echo "Installing Debian packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
# jackd2 asks whether to enable realtime priority: answer no, non-interactively.
echo "jackd2 jackd/tweak_rt_limits boolean false" | debconf-set-selections 2>/dev/null || true
apt-get update -qq >/dev/null 2>&1 || apt-get update
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null || {
  echo "apt-get could not install: ${missing[*]}" >&2
  exit 1
}
