#!/usr/bin/env bash
# README command 1: install what is missing, build the `crep` tool (not the tests), and run the main job:
# `crep render` on the built-in default scene, writing out/crep-colonnade.exr and out/crep-colonnade.png.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
crep_install_packages
CREP_BUILD_TARGET=crep crep_build build
mkdir -p out
./build/examples/crep render --out out/crep-colonnade "$@"
