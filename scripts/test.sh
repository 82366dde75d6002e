#!/usr/bin/env bash
# README command 2: install what is missing, build, and run the whole test suite through ctest.
# CREP_SANITIZE=1 builds and tests the ASan+UBSan configuration in ./build-asan instead.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
crep_install_packages
if [ "${CREP_SANITIZE:-0}" = 1 ]; then
  crep_build build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCREP_SANITIZE=ON
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  # Leak checking for everything that does not load Mesa. With llvmpipe's worker threads alive at
  # exit, LeakSanitizer's stop-the-world intermittently dies ("Tracer caught signal 11"), and Mesa's
  # swrast driver leaks a few strings of its own (lavapipe's LLVM JIT too), so GL and Vulkan tests run
  # with ASan and UBSan but no LSan.
  status=0
  ASAN_OPTIONS=detect_leaks=1 ctest --test-dir build-asan --output-on-failure -j 2 -L cpu "$@" || status=1
  ASAN_OPTIONS=detect_leaks=0 ctest --test-dir build-asan --output-on-failure -j 2 -LE cpu "$@" || status=1
  exit $status
else
  crep_build build
  ctest --test-dir build --output-on-failure -j 2 "$@"
fi
