#!/bin/sh
# CI: ExplicitDeformableModel as an ITK remote module, built as ITK users
# build it, against ITK build trees made from ITK's own sources
# (scripts/build-itk.sh, cached under /var/cache/edm-itk).
#
# For each VERSION:
# 1. through ITKModuleExternal: cmake -S . -B build-itk-VERSION
#    -DITK_DIR=<ITK build tree>, build, and the whole ctest (the module's
#    GoogleTests through ITK's driver, the examples, edmodel's end-to-end
#    tests); a warning about something deprecated fails the stage;
# 2. inside ITK's tree: Modules/Remote/ExplicitDeformableModel with
#    Module_ExplicitDeformableModel=ON, built with ITK, and its edmodel demo
#    run (image and mesh IO registered inside ITK's tree).
#
# Usage: scripts/ci-itk-module.sh VERSION... (default: 5.2.1 5.4.7)
# Debian 12, as root (apt-get). EDM_CI_JOBS sets the parallelism (default 2).
set -eu
cd "$(dirname "$0")/.."
repo=$(pwd)
jobs=${EDM_CI_JOBS:-2}
[ $# -gt 0 ] || set -- 5.2.1 5.4.7

# run LOG COMMAND...: runs COMMAND with its output shown and kept in LOG;
# fails when COMMAND fails.
run() {
  log=$1
  shift
  rc_file="$log.rc"
  { status=0; "$@" 2>&1 || status=$?; echo "$status" > "$rc_file"; } | tee "$log"
  rc=$(cat "$rc_file")
  rm -f "$rc_file"
  return "$rc"
}

# itk_tree VERSION [MODULE_SOURCE_DIR]: the ITK tree scripts/build-itk.sh
# made (the last line it prints); stops the stage when it failed (its status
# would be lost in a pipe: sh has no pipefail).
itk_tree() {
  out=$(scripts/build-itk.sh "$@") || { echo "ci-itk-module: scripts/build-itk.sh $* failed" >&2; exit 1; }
  printf '%s\n' "$out" | tail -n 1
}

summary=""
for version in "$@"; do
  start=$(date +%s)
  itk=$(itk_tree "$version")
  itk_built=$(date +%s)

  # 1. ITKModuleExternal. The VTK module and the benchmarks are the first
  # stages' (this one runs after the ParaView stage, which removes the plain
  # VTK; both build through ITKModuleExternal too when asked).
  build="build-itk-$version"
  mkdir -p "$build"
  run "$build/configure.log" cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DITK_DIR="$itk" \
    -DITK_USE_KWSTYLE=OFF -DITK_USE_CLANG_FORMAT=OFF -DEDM_USE_VTK=OFF -DEDM_BUILD_BENCHMARKS=OFF
  grep -q "building through ITKModuleExternal" "$build/configure.log" || {
    echo "ci-itk-module: ITK $version was not taken through ITKModuleExternal" >&2; exit 1; }
  run "$build/build.log" cmake --build "$build" -j"$jobs"
  if grep -n "warning: .*deprecated" "$build/build.log"; then
    echo "ci-itk-module: deprecation warnings against ITK $version" >&2
    exit 1
  fi
  [ -x "$build/bin/ExplicitDeformableModelGTestDriver" ] || {
    echo "ci-itk-module: ITK's GoogleTest driver was not built" >&2; exit 1; }
  module_built=$(date +%s)
  # The kernel-path suites (the known-answer suites again with each slower
  # SIMD path forced, and under qemu) test the step's code, not the build
  # path: the standalone stage of .ci/run runs them; here they would add
  # about 2.5 minutes per ITK version.
  run "$build/ctest.log" ctest --test-dir "$build" --output-on-failure -j"$jobs" -E "KernelPath"
  tests=$(sed -n 's/.*tests passed, 0 tests failed out of \([0-9]*\).*/\1/p' "$build/ctest.log")
  tested=$(date +%s)

  # 2. Inside ITK's tree.
  intree=$(itk_tree "$version" "$repo")
  demo="$build/intree-demo"
  rm -rf "$demo"
  "$intree/bin/edmodel" demo --output-dir "$demo"
  for f in demo-image.nii.gz demo-force.mha demo-mesh.vtk; do
    [ -s "$demo/$f" ] || { echo "ci-itk-module: the in-tree edmodel demo wrote no $f" >&2; exit 1; }
  done
  end=$(date +%s)

  line="ITK $version: ITK tree $((itk_built - start)) s, module (ITKModuleExternal) $((module_built - itk_built)) s,"
  line="$line ctest $((tested - module_built)) s ($tests tests), ITK tree with the module $((end - tested)) s"
  echo "ci-itk-module: $line"
  summary="$summary$line
"
done
printf 'ci-itk-module:\n%s' "$summary"
