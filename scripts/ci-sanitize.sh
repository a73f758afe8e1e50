#!/bin/sh
# CI stage: the core GoogleTests and edmodel with its end-to-end tests and
# bad-input corpus, built with AddressSanitizer and UndefinedBehaviorSanitizer
# and run clean (any report fails the test that produced it). Core only: no
# VTK, examples or benchmarks, to stay within a few minutes.
# Usage: scripts/ci-sanitize.sh [build directory, default build-sanitize]
set -eu
cd "$(dirname "$0")/.."
build=${1:-build-sanitize}

sanitize="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DCMAKE_CXX_FLAGS="$sanitize" -DCMAKE_C_FLAGS="$sanitize" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DEDM_USE_VTK=OFF -DEDM_BUILD_EXAMPLES=OFF -DEDM_BUILD_BENCHMARKS=OFF
cmake --build "$build" -j2 --target ExplicitDeformableModelGTests edmodel edmodelTestTool

# A report ends the process with an error; leaks are reported at exit.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:exitcode=23:strict_string_checks=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=23"
# AddressSanitizer reserves terabytes of address space: the corpus's 1 GB
# limit (ulimit -v) cannot apply; its 10 s limit still does.
export EDM_NO_MEMORY_LIMIT=1
# Not the packaging test (an install and a downstream build), the real-image
# validation (minutes under the sanitizers) nor the reruns of the suite with
# other kernels (KernelPath): the default kernel's run is sanitized. Nor the
# bit-for-bit comparison with the step before the kernel split
# (ThreeHundredSteps): at -O1 the compiler inlines and contracts into FMAs
# differently, so the bits of a 300-step run differ by rounding; stage 1
# checks them in the Release build, and the sanitizers still run every other
# test of the step. Nor the resolution study (SameParametersGiveTheSameSurface:
# 15 runs up to 65 538 vertices, 6.5 minutes under the sanitizers; the same
# code runs in the sanitized tests of smaller meshes).
ctest --test-dir "$build" --output-on-failure -j2 -E "InstallDownstream|^validation\.|KernelPath|ThreeHundredSteps|SameParametersGiveTheSameSurface"
