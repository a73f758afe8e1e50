#!/bin/sh
# Builds a minimal ITK build tree from ITK's sources, for the remote-module
# builds of ExplicitDeformableModel (scripts/ci-itk-module.sh), and prints its
# path on the last line of standard output.
#
# Usage: scripts/build-itk.sh VERSION [MODULE_SOURCE_DIR]
#   VERSION            5.2.1, 5.4.7 or 6.0b02: ITK-VERSION.tar.xz is unpacked
#                      from $EDM_ITK_SOURCES (default ../shared/third_party
#                      next to this repository).
#   MODULE_SOURCE_DIR  with it, ExplicitDeformableModel is built inside ITK's
#                      tree: Modules/Remote/ExplicitDeformableModel points to
#                      this directory and Module_ExplicitDeformableModel=ON.
#                      Without it, the tree has the modules the module needs
#                      (for a build through ITKModuleExternal).
# EDM_ITK_WRAP_PYTHON=ON (with MODULE_SOURCE_DIR): ITK's Python wrapping
#   (ITK_WRAP_PYTHON, Debian's castxml and swig) of the module and of only the
#   ITK modules it depends on, for 3-D images and meshes of float pixels (no
#   unsigned char, signed short, RGB, RGBA or complex: scripts/ci-itk-python.sh).
#
# Trees are cached between runs under $EDM_ITK_CACHE (default
# /var/cache/edm-itk), in a directory named by the version, the kind of tree
# and a hash of the configuration; compilations go through ccache, so the
# second tree of a version mostly reuses the first one's objects. A tree whose
# last build succeeded is only brought up to date (make), which for the
# in-tree kind rebuilds the module.
#
# Debian 12, as root: installs the packages it needs with apt-get.
# EDM_CI_JOBS sets the build parallelism (default 2).
set -eu
repo=$(cd "$(dirname "$0")/.." && pwd)
version=${1:?usage: scripts/build-itk.sh VERSION [MODULE_SOURCE_DIR]}
module_dir=${2:-}
sources=${EDM_ITK_SOURCES:-$repo/../shared/third_party}
cache=${EDM_ITK_CACHE:-/var/cache/edm-itk}
jobs=${EDM_CI_JOBS:-2}
tarball="$sources/ITK-$version.tar.xz"
[ -f "$tarball" ] || { echo "build-itk: $tarball not found" >&2; exit 2; }
if [ -n "$module_dir" ]; then
  module_dir=$(cd "$module_dir" && pwd)
  [ -f "$module_dir/itk-module.cmake" ] || { echo "build-itk: $module_dir has no itk-module.cmake" >&2; exit 2; }
fi

# Debian's libraries for ITK's third parties, GoogleTest, ccache.
packages="cmake make g++ ccache xz-utils libgdcm-dev libpng-dev libjpeg-dev libtiff-dev zlib1g-dev
  libexpat1-dev libeigen3-dev libgtest-dev"
wrap_python=${EDM_ITK_WRAP_PYTHON:-OFF}
if [ "$wrap_python" = ON ]; then
  [ -n "$module_dir" ] || { echo "build-itk: EDM_ITK_WRAP_PYTHON=ON needs MODULE_SOURCE_DIR" >&2; exit 2; }
  packages="$packages castxml swig4.0 python3-dev python3-numpy"
fi
missing=""
for p in $packages; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "build-itk: installing$missing" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq >&2
  apt-get install -y -qq --no-install-recommends $missing >&2
fi

# The modules of itk-module.cmake (DEPENDS, COMPILE_DEPENDS, TEST_DEPENDS;
# ITKTestKernel brings the other image and mesh IO modules) and
# ITKDeformableMesh, the benchmarks' reference.
modules="ITKCommon ITKMesh ITKImageGradient ITKIOImageBase ITKIOMeshBase ITKIOGDCM ITKIONIFTI ITKIONRRD
  ITKIOMeta ITKIOPNG ITKIOMeshVTK ITKIOMeshOBJ ITKIOMeshOFF ITKIOMeshGifti ITKImageNoise ITKTestKernel
  ITKGoogleTest ITKDeformableMesh"
options="-DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON -DBUILD_TESTING=OFF -DBUILD_EXAMPLES=OFF
  -DITK_BUILD_DEFAULT_MODULES=OFF -DITK_WRAP_PYTHON=OFF -DITK_USE_KWSTYLE=OFF -DITK_USE_CLANG_FORMAT=OFF
  -DITK_USE_SYSTEM_GDCM=ON -DITK_USE_SYSTEM_PNG=ON -DITK_USE_SYSTEM_JPEG=ON -DITK_USE_SYSTEM_TIFF=ON
  -DITK_USE_SYSTEM_ZLIB=ON -DITK_USE_SYSTEM_EXPAT=ON -DITK_USE_SYSTEM_EIGEN=ON -DITK_USE_SYSTEM_GOOGLETEST=ON
  -DITK_USE_SYSTEM_DOUBLECONVERSION=OFF"
case "$version" in
  6.*)
    # ITK 6.0b02's CMake links Debian's GDCM through targets it does not
    # define (ITK::gdcmDICT): its own GDCM, then.
    options=$(echo "$options" | sed 's/-DITK_USE_SYSTEM_GDCM=ON/-DITK_USE_SYSTEM_GDCM=OFF/') ;;
esac
for m in $modules; do
  options="$options -DModule_$m=ON"
done
if [ "$wrap_python" = ON ]; then
  # Only the module and what it depends on (ITK enables those by itself;
  # ITKGroup_Core, on by default, would add ITKTestKernel, the spatial objects,
  # the transforms and more): every enabled module is wrapped.
  kind=python
  options=$(echo "$options" | sed 's/-DITK_WRAP_PYTHON=OFF//; s/-DModule_[A-Za-z0-9]*=ON//g')
  options="$options -DITKGroup_Core=OFF -DModule_ExplicitDeformableModel=ON -DITK_WRAP_PYTHON=ON
    -DITK_USE_SYSTEM_CASTXML=ON -DITK_USE_SYSTEM_SWIG=ON -DPython3_EXECUTABLE=/usr/bin/python3
    -DITK_WRAP_IMAGE_DIMS=3 -DITK_WRAP_unsigned_char=OFF -DITK_WRAP_signed_short=OFF -DITK_WRAP_rgb_unsigned_char=OFF
    -DITK_WRAP_rgba_unsigned_char=OFF -DITK_WRAP_complex_float=OFF"
elif [ -n "$module_dir" ]; then
  kind=intree
  options="$options -DModule_ExplicitDeformableModel=ON"
else
  kind=external
fi
key="$version-$kind-$(printf '%s %s' "$options" "$(g++ -dumpfullversion)" | sha256sum | cut -c1-12)"
# VNL's SSE2 rounding option is defined after ITK reads it for its compiler
# flags: a first configuration compiles without -msse2 and any later one (make
# re-runs CMake when the module's files change) with it, recompiling all of
# ITK. Set to its x86-64 default from the start, the flags never change (not
# part of the key: the configured tree is the same).
options="$options -DVNL_CONFIG_ENABLE_SSE2_ROUNDING=ON"

# One source tree per version, shared by both kinds (same relative paths
# from both build trees: ccache hits across them).
src="$cache/src/ITK-$version"
if [ ! -f "$src/.edm-unpacked" ]; then
  echo "build-itk: unpacking $tarball" >&2
  rm -rf "$src"
  mkdir -p "$cache/src"
  tar -xJf "$tarball" -C "$cache/src"
  [ -d "$src" ] || { echo "build-itk: $tarball does not unpack to ITK-$version/" >&2; exit 2; }
  touch "$src/.edm-unpacked"
fi
if [ "$wrap_python" = ON ] && [ -f "$src/Wrapping/Generators/Python/module_ext.i.in" ] &&
   ! grep -q SWIGPY_SLICEOBJECT "$src/Wrapping/Generators/Python/module_ext.i.in"; then
  # SWIG 4.1 (Debian 12's, package swig4.0) names the slice type SWIGPY_SLICEOBJECT, which
  # ITK before 5.4 does not define (ITK issue 3782, fixed in 5.4 by the same
  # definition): the wrappers do not compile without it. Wrapping only.
  sed -i 's/^# define SWIGPY_SLICE_ARG(obj) ((PyObject\*) (obj))$/&\n# define SWIGPY_SLICEOBJECT PyObject/' \
    "$src/Wrapping/Generators/Python/module_ext.i.in"
  grep -q SWIGPY_SLICEOBJECT "$src/Wrapping/Generators/Python/module_ext.i.in" || {
    echo "build-itk: could not define SWIGPY_SLICEOBJECT in ITK's module_ext.i.in" >&2; exit 2; }
fi
types_py="$src/Wrapping/Generators/Python/itk/support/types.py"
if [ "$wrap_python" = ON ] && [ -f "$types_py" ] && grep -q 'np\.bool)' "$types_py"; then
  # ITK 5.2's Python package names NumPy's boolean type np.bool, an alias
  # NumPy 1.24 (Debian 12's) removed: `import itk` fails with "module 'numpy'
  # has no attribute 'bool'". np.bool_ is the type it meant (ITK 5.3 and
  # later use it). Wrapping only.
  sed -i 's/np\.bool)/np.bool_)/' "$types_py"
  ! grep -q 'np\.bool)' "$types_py" || { echo "build-itk: could not patch $types_py" >&2; exit 2; }
fi
grg="$src/Modules/Filtering/ImageGradient/wrapping/itkGradientRecursiveGaussianImageFilter.wrap"
if [ "$wrap_python" = ON ] && [ -f "$grg" ] && grep -q 'ITKM_I${cv}2${image_dim}' "$grg"; then
  # ITK's wrapping of GradientRecursiveGaussianImageFilter for scalar images
  # names its output ICVF2<dim> (a 2-component covariant vector whatever the
  # image's dimension), which exists only when ITK_WRAP_VECTOR_COMPONENTS
  # includes 2. With ITK_WRAP_IMAGE_DIMS=3 it does not (3;4), the template
  # argument is empty and castxml stops the build. The gradient of a scalar
  # image has one component per image dimension: ICVF<dim><dim>, the filter's
  # default output type. Wrapping only.
  sed -i 's/ITKM_I${cv}2${image_dim}/ITKM_I${cv}${image_dim}${image_dim}/; s/ITKT_I${cv}2${image_dim}/ITKT_I${cv}${image_dim}${image_dim}/' "$grg"
  ! grep -q '${cv}2${image_dim}' "$grg" || {
    echo "build-itk: could not patch $grg" >&2; exit 2; }
fi
if [ -n "$module_dir" ]; then
  # Inside ITK's tree: Modules/Remote/<name> is where ITK's own
  # *.remote.cmake files fetch a remote module to.
  ln -sfn "$module_dir" "$src/Modules/Remote/ExplicitDeformableModel"
fi

build="$cache/$key"
mkdir -p "$build"
export CCACHE_DIR="${CCACHE_DIR:-$cache/ccache}"
export CCACHE_BASEDIR="$cache"
export CCACHE_NOHASHDIR=1
export CCACHE_MAXSIZE="${CCACHE_MAXSIZE:-5G}"
start=$(date +%s)
if [ ! -f "$build/.edm-configured" ]; then
  echo "build-itk: configuring ITK $version ($kind) in $build" >&2
  rm -rf "$build"
  mkdir -p "$build"
  # shellcheck disable=SC2086
  cmake -S "$src" -B "$build" $options \
    -DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache >&2
  touch "$build/.edm-configured"
elif [ -n "$module_dir" ]; then
  # The module's sources may be another checkout than last time, with older
  # time stamps than the objects: rebuild the module, configured afresh.
  rm -rf "$build/Modules/Remote/ExplicitDeformableModel"
  cmake "$build" >&2
fi
echo "build-itk: building ITK $version ($kind) in $build" >&2
cmake --build "$build" -j"$jobs" >&2
end=$(date +%s)
echo "build-itk: ITK $version ($kind) up to date in $((end - start)) s: $build" >&2
echo "$build"
