#!/bin/sh
# Issue 16's robustness check: edmodel segment on Debian mricron-data's ch2
# (brain extraction) and ch2bet (outline), with the defaults and with each
# main parameter halved and doubled; prints Dice and mean boundary distance
# (mm) against ch2bet's brain voxels (validation/edmScore).
# Usage: bench/robustness.sh [BUILD_DIR]   (default: build; about 5 min with the
# collision test, on by default since 2026-12-07: ch2bet with --sigma 2 alone
# takes a minute)
set -eu
build=${1:-build}
templates=/usr/share/mricron/templates
sphere=-0.58,21.4,9.8,40
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for args in "" "--region 0.125" "--region 0.5" "--elasticity 0.15" "--elasticity 0.6" "--rigidity 0.025" \
  "--rigidity 0.1" "--sigma 0.5" "--sigma 2" "--region-sigma 0.5" "--region-sigma 2" \
  "--edge-search-distance 1" "--edge-search-distance 4"; do
  line="${args:-defaults}:"
  for image in ch2 ch2bet; do
    # shellcheck disable=SC2086 # $args holds an option and its value
    "$build/bin/edmodel" segment --quiet --image "$templates/$image.nii.gz" --init-sphere "$sphere" $args \
      --output "$work/surface.vtk"
    score=$("$build/bin/edmScore" score "$work/surface.vtk" "$templates/ch2bet.nii.gz" | awk '{print $2, $4}')
    line="$line $image Dice/mean $score"
  done
  echo "$line"
done
