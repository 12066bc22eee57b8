#!/usr/bin/env bash
# Creates (once) the Python venv for the tools under target/tools-venv with the pinned
# requirements, and prints its python path. Re-installs when requirements.txt changes.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
venv="$root/target/tools-venv"
stamp="$venv/.requirements"
if [ ! -x "$venv/bin/python" ] || ! cmp -s "$root/tools/requirements.txt" "$stamp"; then
  python3 -m venv "$venv" >&2
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r "$root/tools/requirements.txt" >&2
  cp "$root/tools/requirements.txt" "$stamp"
fi
echo "$venv/bin/python"
