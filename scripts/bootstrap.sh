#!/usr/bin/env bash
# Installs what lv3d needs on a fresh Debian/Ubuntu machine: SWI-Prolog and libusb from the
# system's packages, a .venv, and the pinned Python dependencies (torch first, CPU build).
# Idempotent: a stamp file records a finished install of the current constraints.
set -euo pipefail
cd "$(dirname "$0")/.."

need_pkgs=()
command -v swipl >/dev/null 2>&1 || need_pkgs+=(swi-prolog-nox)
ldconfig -p 2>/dev/null | grep -q 'libusb-1.0.so.0' || need_pkgs+=(libusb-1.0-0)
ldconfig -p 2>/dev/null | grep -q 'libgomp.so.1' || need_pkgs+=(libgomp1)
if [ ${#need_pkgs[@]} -gt 0 ]; then
  echo "bootstrap: installing system packages: ${need_pkgs[*]}"
  SUDO=""
  if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
      echo "bootstrap: cannot install ${need_pkgs[*]}: not root and no sudo. Install them with apt-get and rerun." >&2
      exit 1
    fi
  fi
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "bootstrap: no apt-get on this machine; install ${need_pkgs[*]} (SWI-Prolog >= 9, libusb-1.0) by hand and rerun." >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq || { echo "bootstrap: apt-get update failed; install ${need_pkgs[*]} by hand." >&2; exit 1; }
  $SUDO apt-get install -y -qq --no-install-recommends "${need_pkgs[@]}" >/dev/null \
    || { echo "bootstrap: apt-get install ${need_pkgs[*]} failed; install them by hand and rerun." >&2; exit 1; }
fi

PY=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "bootstrap: creating .venv"
  "$PY" -m venv .venv
fi
stamp=.venv/.lv3d-installed
want=$(cat constraints.txt pyproject.toml | sha256sum | cut -d' ' -f1)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$want" ]; then
  echo "bootstrap: installing Python dependencies (a few minutes the first time)"
  .venv/bin/python -m pip install -q --upgrade pip 2>/dev/null || true
  # torch before kornia, pinned to the CPU build: an unpinned torch pulls GBs of CUDA packages.
  .venv/bin/python -m pip install -q -c constraints.txt "torch==2.13.0"
  .venv/bin/python -m pip install -q -c constraints.txt -e ".[test]"
  echo "$want" > "$stamp"
fi
