#!/bin/sh
# Build the wheels the Blender extension bundles (see the README, "Blender add-on"), then the extension zip.
#   addon/build_wheels.sh [BLENDER]   (BLENDER: path of a blender binary, for `extension build`)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
python=${PYTHON:-"$root/.venv/bin/python"}
mkdir -p "$here/wheels"
"$python" -m pip wheel --no-deps -w "$here/wheels" "$root"
"$python" -m pip download --only-binary=:all: --python-version 3.11 --platform manylinux2014_x86_64 \
    --no-deps -d "$here/wheels" "PyYAML==6.0.2"
if [ "${1:-}" ]; then
    "$1" --command extension build --source-dir "$here" --output-dir "$root/dist"
fi
