#!/usr/bin/env bash
# Prepare this checkout to run ribbonwave: the Debian packages that Qt and VTK need at
# run time (installed when running as root, otherwise printed as a sudo command), then
# .venv with ribbonwave installed editable with its test extras. Fast when already done.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# Run-time libraries of the PySide6 and VTK wheels that a minimal Debian 12 lacks
# (found with ldd on Qt's xcb platform plugin and QtGui, and QT_DEBUG_PLUGINS=1), Mesa
# for software OpenGL, libXcursor (which VTK loads for its mouse cursors), and Xvfb for
# machines without a display.
debian_packages=(
  xvfb xauth
  libgl1 libglx-mesa0 libgl1-mesa-dri libegl1
  libglib2.0-0 libdbus-1-3 libfontconfig1 libfreetype6
  libx11-6 libx11-xcb1 libxcursor1 libxkbcommon0 libxkbcommon-x11-0
  libxcb1 libxcb-cursor0 libxcb-glx0 libxcb-icccm4 libxcb-image0 libxcb-keysyms1
  libxcb-randr0 libxcb-render0 libxcb-render-util0 libxcb-shape0 libxcb-shm0
  libxcb-sync1 libxcb-util1 libxcb-xfixes0 libxcb-xkb1
)

install_debian_packages() {
  if ! command -v dpkg-query >/dev/null; then
    echo "setup.sh: not a Debian system; make sure Xvfb, Mesa OpenGL and Qt's xcb libraries are installed" >&2
    return
  fi
  local packages=("${debian_packages[@]}") missing=() package
  python3 -c 'import ensurepip' 2>/dev/null || packages+=(python3-venv)
  for package in "${packages[@]}"; do
    [[ $(dpkg-query -W -f='${db:Status-Status}' "$package" 2>/dev/null) == installed ]] || missing+=("$package")
  done
  if ((${#missing[@]} == 0)); then
    return
  fi
  if [[ $(id -u) -ne 0 ]]; then
    echo "setup.sh: missing Debian packages; install them with:" >&2
    echo "  sudo apt-get install -y --no-install-recommends ${missing[*]}" >&2
    exit 1
  fi
  echo "setup.sh: installing Debian packages: ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive DEBCONF_NOWARNINGS=yes
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

install_debian_packages

venv="$root/.venv"
stamp="$venv/.ribbonwave-installed"
if [[ ! -x "$venv/bin/python" ]]; then
  python3 -c 'import sys; sys.exit(sys.version_info < (3, 11))' ||
    { echo "setup.sh: ribbonwave needs Python >= 3.11, python3 is $(python3 -V)" >&2; exit 1; }
  echo "setup.sh: creating $venv" >&2
  python3 -m venv "$venv"
fi
if [[ ! -e "$stamp" || "$root/pyproject.toml" -nt "$stamp" ]]; then
  echo "setup.sh: installing ribbonwave and its dependencies into $venv" >&2
  # pip's log is shown only on failure: an editable build always prints setuptools notices.
  if ! log=$("$venv/bin/python" -m pip install --disable-pip-version-check --editable "$root[test]" 2>&1); then
    echo "$log" >&2
    exit 1
  fi
  # numba compiles the structural alignment's kernels on their first use (a minute or two on a
  # busy machine) and caches them: done here, the first comparison or search does not wait.
  echo "setup.sh: compiling the structural alignment" >&2
  "$venv/bin/python" - <<'PY'
import numpy as np
from core.analysis.fold_alignment import align_folds
from core.analysis.tm_align import screen
turns = np.arange(40.0)
helix = np.stack([2.3 * np.cos(1.75 * turns), 2.3 * np.sin(1.75 * turns), 1.5 * turns], axis=1)
align_folds(helix, helix[::-1].copy())
screen(helix, helix, np.array([0]), np.array([40]), 4)
PY
  touch "$stamp"
fi
