#version 450 core
// Test fixture: a compile error in an included file (compile_error_inc.glsl, line 4).
#include "compile_error_inc.glsl"
layout(local_size_x = 1) in;
void main() { crep_test_broken(); }
