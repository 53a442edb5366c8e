#!/usr/bin/env bash
# Shared set-up for scripts/serve and scripts/test: Debian packages, then a
# virtual environment in .venv with Opaline installed into it. Idempotent and
# quick when nothing changed, so both commands can always call it.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

RUNTIME_DEBS=(libegl1 libegl-mesa0 libgl1 libgl1-mesa-dri libgles2 libosmesa6)
as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

install_debs() {
  local missing=()
  for pkg in "$@"; do
    dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
  done
  if [ ${#missing[@]} -gt 0 ]; then
    echo "setup: installing Debian packages: ${missing[*]}" >&2
    as_root apt-get update -qq
    DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
  fi
}

install_debs "${RUNTIME_DEBS[@]}"
if [ -n "${OPALINE_EXTRA_DEBS:-}" ]; then
  # shellcheck disable=SC2086
  install_debs $OPALINE_EXTRA_DEBS
fi

PY=${PYTHON:-python3}
if ! "$PY" -c 'import venv, ensurepip' 2>/dev/null; then
  install_debs python3-venv python3-pip
fi

extras=${OPALINE_EXTRAS:-}
stamp=".venv/.opaline-stamp"
want="$(cat pyproject.toml | sha256sum | cut -c1-16)-${extras}"
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
if [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  echo "setup: installing Python dependencies into .venv" >&2
  .venv/bin/python -m pip install -q --upgrade pip >&2
  .venv/bin/python -m pip install -q -e ".${extras:+[$extras]}" >&2
  echo "$want" > "$stamp"
fi
