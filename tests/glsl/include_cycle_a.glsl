// Test fixture: include cycle a -> b -> a.
#include "include_cycle_b.glsl"
