/* include_b
#include "not_a_directive.glsl" (inside a comment) */
#include "test/shadowed.glsl" // relative: test/sub/test/shadowed.glsl
const int crep_test_b = 2;
