// Test fixture: include resolution (relative first, root fallback, once-only, #version).
#version 450 core
#include "include_a.glsl"
#include "test/shadowed.glsl" // root: there is no test/test/shadowed.glsl
#include "include_a.glsl"
layout(local_size_x = 1) in;
void main() {}
