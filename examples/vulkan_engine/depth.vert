// The engine's depth-only vertex shader: world-space positions through one clip-from-world matrix.
#version 450
layout(push_constant) uniform Push {
  mat4 clipFromWorld;
};
layout(location = 0) in vec3 position;
void main() { gl_Position = clipFromWorld * vec4(position, 1.0); }
