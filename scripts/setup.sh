#!/usr/bin/env bash
# Prepare this checkout to run ribbonwave: the Debian packages that Qt and VTK need at
# run time (installed when running as root, otherwise printed as a sudo command), then
# .venv with the exact versions of requirements/lock.txt and ribbonwave installed editable.
# Fast when already done; .venv is made again from scratch when the lock changes.
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
# The extras that scripts/lock.sh locks besides ribbonwave's own dependencies.
locked_extras=(test cluster)

# What .venv was built from: the sha256 of the lock and of pyproject.toml (not their
# times, which a clone sets to now).
sums=$(cd "$root" && sha256sum requirements/lock.txt pyproject.toml)
built=$(cat "$stamp" 2>/dev/null || true)
if [[ $built == "$sums" ]]; then
  exit 0
fi

# pip's log is shown only on failure: an editable build always prints setuptools notices.
pip_install() {
  local log
  if ! log=$("$venv/bin/python" -m pip install --disable-pip-version-check "$@" 2>&1); then
    echo "$log" >&2
    exit 1
  fi
}

# The lock must hold every dependency of the installed packages (pip check) and of
# ribbonwave's locked extras (which pip check skips), in versions that they allow.
check_lock() {
  local status=0 log
  log=$("$venv/bin/python" -m pip check --disable-pip-version-check) || { echo "$log"; status=1; }
  "$venv/bin/python" - "${locked_extras[@]}" <<'PY' || status=1
import sys
from importlib.metadata import PackageNotFoundError, distribution
from packaging.requirements import Requirement

def satisfied(name, extras):
    """Whether every requirement of `name` with `extras` is installed in a version it allows."""
    ok = True
    for requirement in map(Requirement, distribution(name).requires or []):
        if requirement.marker and not any(requirement.marker.evaluate({"extra": e}) for e in extras):
            continue
        requirement.marker = None
        try:
            version = distribution(requirement.name).version
        except PackageNotFoundError:
            print(f"{name} requires {requirement}, which is not installed")
            ok = False
            continue
        if not requirement.specifier.contains(version, prereleases=True):
            print(f"{name} requires {requirement}, but {requirement.name} {version} is installed")
            ok = False
        elif requirement.extras:
            ok = satisfied(requirement.name, ["", *requirement.extras]) and ok
    return ok

sys.exit(not satisfied("ribbonwave", ["", *sys.argv[1:]]))
PY
  return "$status"
}

# pip has no sync: a package dropped from the lock would stay in .venv, so a new lock
# gets a new .venv.
if [[ -e "$venv" && ${built%%$'\n'*} != "${sums%%$'\n'*}" ]]; then
  if [[ -n $built ]]; then
    echo "setup.sh: requirements/lock.txt changed since $venv was built; creating it again" >&2
  else
    echo "setup.sh: $venv is not (all) from requirements/lock.txt; creating it again" >&2
  fi
  rm -rf "$venv"
fi
if [[ ! -x "$venv/bin/python" ]]; then
  python3 -c 'import sys; sys.exit(sys.version_info < (3, 11))' ||
    { echo "setup.sh: ribbonwave needs Python >= 3.11, python3 is $(python3 -V)" >&2; exit 1; }
  echo "setup.sh: creating $venv with the versions of requirements/lock.txt" >&2
  python3 -m venv "$venv"
  # Each package is pinned with its hashes, its dependencies too: nothing else comes in.
  pip_install --require-hashes --no-deps --requirement "$root/requirements/lock.txt"
fi
echo "setup.sh: installing ribbonwave into $venv" >&2
# Without build isolation: the build backend is the lock's setuptools, installed above.
pip_install --no-deps --no-build-isolation --editable "$root"
if ! log=$(check_lock 2>&1); then
  echo "$log" >&2
  echo "setup.sh: requirements/lock.txt does not satisfy pyproject.toml; run bash scripts/lock.sh" >&2
  exit 1
fi

# numba compiles the structural alignment's kernels on their first use (a minute or two on a
# busy machine) and caches them: done here, the first comparison or search does not wait.
echo "setup.sh: compiling the structural alignment and the fold search" >&2
"$venv/bin/python" - "$root/resources/examples/1UBQ.pdb" <<'PY'
import sys
from core.analysis.fold_alignment import align_folds
from core.analysis.fold_index import index_structure
from core.analysis.fold_search import search
from core.protein.reading import read_structure
index = index_structure(read_structure(sys.argv[1]))
ca, codes = index.chain(0)
search(index, ca, codes.tobytes().decode())
align_folds(ca, ca[::-1].copy())
PY
echo "$sums" >"$stamp"
