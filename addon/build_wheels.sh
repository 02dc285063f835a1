#!/bin/sh
# Build the extension zip(s): the adfkit wheel plus its pure and binary dependencies for
# Linux x64, macOS arm64 and Windows x64 (Python 3.11, Blender 4.2-5.0), the manifest's
# `wheels`/`platforms` lists rewritten from what was downloaded, then Blender's own
# `extension build` (from a Blender binary if given, else the copy inside the bpy wheel).
#   addon/build_wheels.sh [BLENDER]
# See the README, "Blender add-on".
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
python=${PYTHON:-"$root/.venv/bin/python"}
rm -rf "$here/wheels" && mkdir -p "$here/wheels"
"$python" -m pip wheel --quiet --no-deps -w "$here/wheels" "$root"
pins="PyYAML==6.0.3 jsonschema==4.26.0 attrs==26.1.0 referencing==0.37.0 jsonschema-specifications==2025.9.1
      rpds-py==2026.9.1 typing-extensions==4.16.0 jsonschema-rs==0.60.3"
# adfkit.geometry ("Generate convex collision", "Fit collision primitive", "Estimate inertia"):
# the versions the test suite runs with; numpy is Blender's own (1.26 in Blender 4.2-5.0).
geometry_pins="trimesh==5.2.0 manifold3d==3.5.4 coacd==1.0.14 scipy==1.17.1 networkx==3.6.1"
# each platform as the tags its wheels carry (manylinux_2_28 for manifold3d and scipy, macOS 12+ for scipy)
for platforms in "manylinux2014_x86_64 manylinux_2_28_x86_64" "macosx_11_0_arm64 macosx_12_0_arm64 macosx_14_0_arm64" \
                 "win_amd64"; do
    flags=""
    for p in $platforms; do flags="$flags --platform $p"; done
    # shellcheck disable=SC2086
    "$python" -m pip download --quiet --only-binary=:all: --python-version 3.11 $flags \
        --no-deps -d "$here/wheels" $pins $geometry_pins
done
"$python" "$here/manifest_wheels.py" "$here"
if [ "${1:-}" ]; then
    "$1" --command extension build --source-dir "$here" --output-dir "$root/dist" --split-platforms
else
    ext=$("$python" -c "import importlib.util as u, pathlib; print(next(pathlib.Path(u.find_spec('bpy').submodule_search_locations[0]).glob('*/scripts/addons_core/bl_pkg/cli/blender_ext.py')))")
    mkdir -p "$root/dist"
    "$python" "$ext" build --source-dir "$here" --output-dir "$root/dist" --split-platforms
fi
