// Test fixture: a malformed #include (angle brackets are not supported).
#include <crep/common.glsl>
