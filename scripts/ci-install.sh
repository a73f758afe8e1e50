#!/bin/sh
# CI: the project installed to its configured prefix (by default /usr/local)
# is usable without environment variables, then removed again.
#
# - `cmake --install BUILD_DIR` to the build's CMAKE_INSTALL_PREFIX;
# - the installed edmodel runs (`edmodel --version`);
# - with the VTK module's Python package: /usr/bin/python3, started in / with
#   PYTHONPATH and LD_LIBRARY_PATH unset, imports edmodel from the prefix and
#   makes a vtkDeformableMesh;
# - with the ParaView plugin: pvpython, PV_PLUGIN_PATH unset, loads the
#   installed plugin through its plugin configuration file
#   (PV_PLUGIN_CONFIG_FILE=<prefix>/lib/paraview-X.Y/plugins/ExplicitDeformableModel.plugins.xml,
#   ParaView's own mechanism for plugins outside its prefix) and runs its
#   Iterative Warp filter;
# - then every installed file (install_manifest.txt) and every directory the
#   install created is removed, so that later stages and runs do not see them
#   (EDM_CI_KEEP_INSTALL=1 keeps them).
#
# Usage: scripts/ci-install.sh BUILD_DIR
set -eu
build=${1:?usage: scripts/ci-install.sh BUILD_DIR}
build=$(cd "$build" && pwd)
prefix=$(sed -n 's/^CMAKE_INSTALL_PREFIX:[A-Z]*=//p' "$build/CMakeCache.txt")
[ -n "$prefix" ] || { echo "ci-install: no CMAKE_INSTALL_PREFIX in $build/CMakeCache.txt" >&2; exit 2; }
start=$(date +%s)

before=$(mktemp)
mkdir -p "$prefix"
find "$prefix" -type d | sort > "$before"
cleanup() {
  if [ "${EDM_CI_KEEP_INSTALL:-0}" != 1 ] && [ -f "$build/install_manifest.txt" ]; then
    xargs -d '\n' rm -f < "$build/install_manifest.txt"
    # New directories, deepest first.
    find "$prefix" -type d | sort | comm -23 - "$before" | sort -r | while IFS= read -r d; do
      rmdir "$d" 2>/dev/null || true
    done
    echo "ci-install: removed the install from $prefix"
  fi
  rm -f "$before"
}
trap cleanup EXIT

cmake --install "$build" > "$build/install.log"
echo "ci-install: installed $(wc -l < "$build/install_manifest.txt") files to $prefix"

"$prefix/bin/edmodel" --version

package=$(grep '/edmodel/__init__.py$' "$build/install_manifest.txt" || true)
if [ -n "$package" ]; then
  # Not from the source or build tree: in / with no search path set.
  imported=$(cd / && env -u PYTHONPATH -u LD_LIBRARY_PATH /usr/bin/python3 -c \
    'import edmodel; m = edmodel.vtkDeformableMesh(); print(edmodel.__file__, m.GetClassName())')
  echo "ci-install: /usr/bin/python3 imported $imported"
  case "$imported" in
    "$package "*) ;;
    *) echo "ci-install: python3 did not import the installed edmodel ($package)" >&2; exit 1 ;;
  esac
fi

plugins_file=$(grep '/ExplicitDeformableModel.plugins.xml$' "$build/install_manifest.txt" || true)
if [ -n "$plugins_file" ]; then
  pvpython=$(sed -n 's/^EDM_PVPYTHON_EXECUTABLE:[A-Z]*=//p' "$build/CMakeCache.txt")
  [ -x "$pvpython" ] || pvpython=$(command -v pvpython)
  # The plugin from the prefix only: no PV_PLUGIN_PATH, started in /.
  output=$(cd / && env -u PV_PLUGIN_PATH -u PYTHONPATH -u LD_LIBRARY_PATH PV_PLUGIN_CONFIG_FILE="$plugins_file" \
    "$pvpython" --force-offscreen-rendering -c '
from paraview import servermanager, simple
for f in ("IterativeWarp", "DeformableMesh", "ForceField"):
    assert hasattr(simple, f), "no " + f + " filter"
warp = simple.IterativeWarp(Input=simple.Sphere(), NumberOfIterations=2, StepLength=0.1)
warp.UpdatePipeline()
n = warp.GetDataInformation().GetNumberOfPoints()
assert n > 0, "Iterative Warp gave no points"
info = servermanager.vtkSMProxyManager.GetProxyManager().GetPluginManager().GetLocalInformation()
files = [info.GetPluginFileName(i) for i in range(info.GetNumberOfPlugins())
         if info.GetPluginName(i) == "ExplicitDeformableModelPlugin" and info.GetPluginLoaded(i)]
print("loaded", files[0] if files else "nothing", "points", n)
' 2>&1 || true)
  loaded=$(printf '%s\n' "$output" | grep '^loaded' || true)
  echo "ci-install: pvpython $loaded"
  case "$loaded" in
    "loaded $prefix/"*) ;;
    *) printf '%s\n' "$output" >&2
       echo "ci-install: pvpython did not load the installed plugin through $plugins_file" >&2; exit 1 ;;
  esac
fi
echo "ci-install: $(($(date +%s) - start)) s"
