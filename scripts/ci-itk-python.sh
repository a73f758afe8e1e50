#!/bin/sh
# The module's ITK Python wrapping (wrapping/*.wrap), built and tested: an ITK
# tree with ITK_WRAP_PYTHON=ON and ExplicitDeformableModel inside it
# (scripts/build-itk.sh with EDM_ITK_WRAP_PYTHON=ON: Debian's castxml and SWIG,
# Python 3.11; only the ITK modules the module depends on; 3-D images and
# meshes), then wrapping/test/itkDeformableMeshFilterPythonTest.py, the seed's
# case through `import itk` with its known answer.
#
# ITK 5.2.1 (Debian 12's version) is the default and the one that works here:
# ITK 5.4 and later require SWIG 4.2 or newer (Debian 12 has 4.1.0) and ITK's
# own SWIG build downloads its sources, which this machine cannot.
#
# Usage: scripts/ci-itk-python.sh [VERSION, default 5.2.1]
# Debian 12, as root (apt-get). EDM_CI_JOBS sets the parallelism (default 2).
# The tree is cached under /var/cache/edm-itk like the others; on a fresh
# 2-core machine its build is long (see docs/building.md for the measured run).
set -eu
cd "$(dirname "$0")/.."
repo=$(pwd)
version=${1:-5.2.1}

start=$(date +%s)
itk=$(EDM_ITK_WRAP_PYTHON=ON scripts/build-itk.sh "$version" "$repo") || {
  echo "ci-itk-python: the wrapped ITK $version tree did not build ($(($(date +%s) - start)) s)" >&2; exit 1; }
itk=$(printf '%s\n' "$itk" | tail -n 1)
built=$(date +%s)

python_dir="$itk/Wrapping/Generators/Python"
[ -f "$python_dir/itk/__init__.py" ] || { echo "ci-itk-python: no itk package in $python_dir" >&2; exit 1; }
ls "$python_dir"/itk/*ExplicitDeformableModel* > /dev/null 2>&1 || ls "$itk"/lib/*ExplicitDeformableModel*Python* > /dev/null 2>&1 || {
  echo "ci-itk-python: the module's Python wrapping was not built in $itk" >&2; exit 1; }
# The interpreter ITK was wrapped for (build-itk.sh: /usr/bin/python3), not
# whichever python3 comes first on PATH (a pyenv shim has neither these
# headers' ABI nor numpy).
python=${EDM_PYTHON:-/usr/bin/python3}
status=0
env PYTHONPATH="$python_dir:$itk/lib" "$python" wrapping/test/itkDeformableMeshFilterPythonTest.py || status=$?
end=$(date +%s)
echo "ci-itk-python: ITK $version wrapped tree $((built - start)) s, Python test $((end - built)) s, status $status"
exit $status
