#!/usr/bin/env bash
# Make requirements/lock.txt from pyproject.toml: the exact versions, with their hashes, of
# ribbonwave's dependencies, its test and cluster extras and its build backend (setuptools),
# for Python 3.11 on Linux x86_64 (glibc 2.36, Debian 12), wheels only. scripts/setup.sh
# installs them. Versions already in the lock stay while pyproject.toml allows them;
# `--upgrade` moves every one to the newest it allows. uv, pinned, is installed into
# .lock-tools/ on the first run.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
uv_version=0.13.9
tools="$root/.lock-tools"

upgrade=()
case "${1:-}" in
  "") ;;
  --upgrade) upgrade=(--upgrade) ;;
  *) echo "usage: bash scripts/lock.sh [--upgrade]" >&2; exit 2 ;;
esac

if [[ $("$tools/bin/uv" --version 2>/dev/null) != "uv $uv_version "* ]]; then
  echo "lock.sh: installing uv $uv_version into $tools" >&2
  rm -rf "$tools"
  python3 -m venv "$tools"
  if ! log=$("$tools/bin/python" -m pip install --disable-pip-version-check "uv==$uv_version" 2>&1); then
    echo "$log" >&2
    exit 1
  fi
fi

# [build-system] requires of pyproject.toml: setup.sh installs ribbonwave itself without
# build isolation, with the setuptools of the lock.
build_requires=$("$tools/bin/python" -c '
import sys, tomllib
with open(sys.argv[1], "rb") as file:
    print("\n".join(tomllib.load(file)["build-system"]["requires"]))
' "$root/pyproject.toml")

# The benchmark extra (ProDy) is left out: ProDy has no Linux wheel for Python 3.11, and
# building it needs a C compiler and Python's headers.
cd "$root"
printf '%s\n' "$build_requires" |
  "$tools/bin/uv" pip compile --quiet pyproject.toml - \
    --extra test --extra cluster \
    --python-version 3.11 --python-platform x86_64-manylinux_2_36 \
    --only-binary :all: --emit-build-options --generate-hashes "${upgrade[@]}" \
    --custom-compile-command "bash scripts/lock.sh" \
    --output-file requirements/lock.txt
echo "lock.sh: wrote requirements/lock.txt ($(grep -c '^[a-z0-9]' requirements/lock.txt) packages)" >&2
