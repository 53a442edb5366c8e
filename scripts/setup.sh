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

# The stamp is pyproject.toml's hash and the extras installed with it. Extras already
# there are enough: scripts/serve after scripts/test (whose extras include the runtime's)
# must not reinstall, and so need no network, every time the two alternate.
extras=${OPALINE_EXTRAS:-}
stamp=".venv/.opaline-stamp"
hash="$(sha256sum < pyproject.toml | cut -c1-16)"
have="$(cat "$stamp" 2>/dev/null || true)"
have_extras=""
[ "${have%%-*}" = "$hash" ] && have_extras="${have#*-}"
union="$have_extras"
for extra in ${extras//,/ }; do
  case ",$union," in *",$extra,"*) ;; *) union="${union:+$union,}$extra" ;; esac
done
if [ ! -x .venv/bin/python ]; then
  "$PY" -m venv .venv
fi
if [ "$have" != "$hash-$union" ]; then
  echo "setup: installing Python dependencies into .venv" >&2
  .venv/bin/python -m pip install -q --upgrade pip >&2
  .venv/bin/python -m pip install -q -e ".${union:+[$union]}" >&2
  echo "$hash-$union" > "$stamp"
fi
