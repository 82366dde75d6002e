// include_a
#include "sub/include_b.glsl"
const int crep_test_a = 1;
