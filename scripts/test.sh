#!/usr/bin/env bash
# README command 2: install what is missing, build, and run the whole test suite through ctest.
# CREP_SANITIZE=1 builds and tests the ASan+UBSan configuration in ./build-asan instead.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
crep_install_packages
if [ "${CREP_SANITIZE:-0}" = 1 ]; then
  crep_build build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCREP_SANITIZE=ON
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest --test-dir build-asan --output-on-failure -j 2 "$@"
else
  crep_build build
  ctest --test-dir build --output-on-failure -j 2 "$@"
fi
