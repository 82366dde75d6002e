// Test fixture: an include that does not exist.

#include "does_not_exist.glsl"
