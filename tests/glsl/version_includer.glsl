// Test fixture: #version in an included file is an error.
#include "version_included.glsl"
